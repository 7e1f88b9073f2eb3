#include "report/html_report.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

#include "ir/dump.h"

namespace substratec::html {

namespace {

/// The longest source listed in the page (a larger one is left out; its
/// diagnostics still show line:col and the pointer).
constexpr std::size_t kMaxListedSource = std::size_t{1} << 20;
/// Characters of a node id shown in a tree box (the whole id is its tooltip).
constexpr std::size_t kBoxIdChars = 22;

constexpr const char* kStyle = R"(
:root{color-scheme:light;--ink:#1d232b;--muted:#5f6b7a;--line:#d5dbe3;--panel:#f6f8fa;--accent:#2f6fde;--bad:#c62828}
*{box-sizing:border-box}
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:var(--ink);margin:0;background:#fff}
header.page{padding:18px 28px;border-bottom:1px solid var(--line);background:var(--panel)}
header.page h1{margin:0;font-size:22px}
header.page p{margin:4px 0 0;color:var(--muted)}
nav.toc{padding:10px 28px;border-bottom:1px solid var(--line);font-size:13px;display:flex;flex-wrap:wrap;gap:4px 14px}
main{padding:0 28px 40px}
section.material,section.scene{border-bottom:1px solid var(--line);padding:18px 0}
h2{font-size:19px;margin:6px 0 10px}
h3{font-size:15px;margin:18px 0 8px}
a{color:var(--accent);text-decoration:none}a:hover{text-decoration:underline}
table{border-collapse:collapse;font-size:13px;margin:4px 0}
th,td{border:1px solid var(--line);padding:3px 8px;text-align:left;vertical-align:top}
th{background:var(--panel);font-weight:600}
td.num{text-align:right;font-variant-numeric:tabular-nums}
code{font:12px/1.3 ui-monospace,"DejaVu Sans Mono",monospace}
.summary{display:grid;grid-template-columns:max-content auto;gap:2px 16px;font-size:13px}
.summary dt{color:var(--muted)}.summary dd{margin:0}
.trees{display:flex;flex-wrap:wrap;gap:24px;align-items:flex-start}
.trees figure{margin:0;overflow-x:auto;max-width:100%}
figcaption{font-weight:600;margin-bottom:4px}
.diag{list-style:none;padding:0;margin:0}
.diag li{padding:4px 8px;margin:3px 0;border-left:4px solid var(--line);background:var(--panel)}
.diag li.error{border-color:var(--bad)}.diag li.warning{border-color:#e0a100}.diag li.note{border-color:var(--accent)}
.sev{font-weight:600;text-transform:uppercase;font-size:11px;margin-right:6px}
.badge{display:inline-block;padding:0 6px;margin:1px 2px;border-radius:8px;background:#e4ecfb;font-size:12px}
.failed{color:var(--bad);font-weight:600}
pre.source{font:12px/1.35 ui-monospace,"DejaVu Sans Mono",monospace;background:var(--panel);padding:8px;overflow-x:auto;max-height:480px}
pre.source span{display:block}pre.source span:target{background:#fff3c4}
pre.source span::before{content:attr(data-line);display:inline-block;width:4em;color:var(--muted)}
.previews{display:flex;flex-wrap:wrap;gap:12px}
.previews figure{margin:0;text-align:center;font-size:12px}
svg text{font-family:system-ui,"DejaVu Sans",sans-serif}
)";

/// The colours of the byte bar's parts and of the feature badges' boxes.
constexpr std::array<const char*, 6> kPartColours = {"#7b8794", "#2f6fde", "#e07b00", "#2e9e5b", "#d5dbe3", "#8e44ad"};
constexpr std::array<const char*, 6> kPartNames = {"header", "closure data", "feature data",
                                                   "shared bases", "padding", "top layer"};
constexpr std::array<const char*, 8> kBasisColours = {"#2e9e5b", "#8e44ad", "#c0392b", "#16a085",
                                                      "#d35400", "#2c3e50", "#7f8c8d", "#b7950b"};


/// A node id for an element id or fragment: material index, view and the id.
std::string elementId(int material, std::string_view view, std::string_view node) {
  return fmt::format("m{}-{}-{}", material, view, node);
}

std::string sourceAnchor(int material, int line) { return fmt::format("m{}-src-L{}", material, line); }

/// The source line `pointer` locates, 0 when none (no locator, or no listing).
int lineOf(const MaterialPage& p, const std::string& pointer) {
  if (!p.locator || p.sourceText.empty() || p.sourceText.size() > kMaxListedSource) return 0;
  int line = 0, column = 0;
  return p.locator->locate(pointer, line, column) ? line : 0;
}

std::string shortId(const std::string& id) {
  return id.size() <= kBoxIdChars ? id : id.substr(0, kBoxIdChars - 1) + "\u2026";
}

// ----- The tree diagram -------------------------------------------------------

/// Where each tree node's box goes: leaves left to right in pre-order (the
/// tree's left-to-right order), an operator above the middle of its children,
/// rows by depth.
struct TreeLayout {
  std::vector<double> x;   // box centre, in leaf slots
  std::vector<int> depth;  // row
  int leaves = 0, rows = 0;
};

TreeLayout layoutTree(const Material& m, const TreeInfo& t) {
  TreeLayout L;
  L.x.assign(m.nodes.size(), 0);
  L.depth.assign(m.nodes.size(), 0);
  for (int n : t.preorder) {
    const TreeNode& node = m.nodes[n];
    L.depth[n] = t.depth[n];
    L.rows = std::max(L.rows, t.depth[n] + 1);
    if (node.left < 0 && node.right < 0) L.x[n] = L.leaves++;
  }
  for (auto it = t.preorder.rbegin(); it != t.preorder.rend(); ++it) {  // children before parents
    const TreeNode& node = m.nodes[*it];
    if (node.left >= 0 && node.right >= 0) L.x[*it] = (L.x[node.left] + L.x[node.right]) / 2;
    else if (node.left >= 0) L.x[*it] = L.x[node.left];
    else if (node.right >= 0) L.x[*it] = L.x[node.right];
  }
  return L;
}

constexpr double kSlotWidth = 176, kBoxWidth = 162, kRowHeight = 108, kBoxHeight = 78, kMargin = 10;

/// A badge of a tree box: its text, its fill, and whether the text is white.
struct Badge {
  std::string text;
  const char* fill;
  bool dark;
};

/// The badges of a tree box: a slab's features and its basis (a shared
/// basis in its own colour).
std::vector<Badge> boxBadges(const Material& m, const TreeNode& node) {
  std::vector<Badge> badges;
  if (node.op != TreeOp::Slab || node.slab < 0) return badges;
  const Slab& s = m.slabs[node.slab];
  for (int b = 0; b < kFeatureCount; ++b)
    if (s.features & (1u << b)) badges.push_back({std::string(featureName(b)), "#e4ecfb", false});
  if (s.basis >= 0 && s.basis < static_cast<int>(m.bases.size())) {
    const bool shared = m.bases[s.basis].slabs.size() > 1;
    badges.push_back({fmt::format("basis {}{}", s.basis, shared ? " shared" : ""),
                      shared ? kBasisColours[s.basis % kBasisColours.size()] : "#eef0f3", shared});
  }
  return badges;
}

/// One box: the operator, the node id, the closure it becomes and its badges
/// (the node's link to its source line is in the feature lines: featureTable).
std::string treeBox(int index, std::string_view view, const CompileResult& r, int n, double cx, double top) {
  const Material& m = r.material;
  const TreeInfo& t = r.tree;
  const TreeNode& node = m.nodes[n];
  const bool slab = node.op == TreeOp::Slab;
  const double left = cx - kBoxWidth / 2;
  std::string o = fmt::format(R"(<g class="node" id="{}" data-node="{}" data-op="{}">)",
                              escape(elementId(index, view, node.id)), escape(node.id), escape(nodeOpName(m, node)));
  o += fmt::format("<title>{} ({}){}</title>", escape(node.id), escape(nodeOpName(m, node)),
                   node.pointer.empty() ? "" : " at " + escape(node.pointer));
  o += fmt::format(R"(<rect x="{:.1f}" y="{:.1f}" width="{}" height="{}" rx="6" fill="{}" stroke="{}"/>)", left, top,
                   kBoxWidth, kBoxHeight, slab ? "#f3f7ff" : "#fff8ec", slab ? "#2f6fde" : "#e07b00");
  std::string label = std::string(nodeOpName(m, node));
  if (slab && node.slab >= 0 && t.bsdfId[node.slab] >= 0 && !isUnlitLeaf(m, node))
    label += fmt::format(" \u00b7 closure {}", t.bsdfId[node.slab]);
  o += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" fill="#5f6b7a">{}</text>)", left + 6, top + 14,
                   escape(label));
  o += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="13" font-weight="600">{}</text>)", left + 6, top + 31,
                   escape(shortId(node.id)));
  double bx = left + 6, by = top + 40;
  for (const Badge& badge : boxBadges(m, node)) {
    const double w = 6.2 * static_cast<double>(badge.text.size()) + 8;
    if (bx + w > left + kBoxWidth - 4 && bx > left + 6) bx = left + 6, by += 17;
    if (by + 14 > top + kBoxHeight) break;  // the rest are in the feature lines
    o += fmt::format(R"(<rect class="badge" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="14" rx="7" fill="{}"/>)", bx,
                     by, w, badge.fill);
    o += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="10.5" fill="{}">{}</text>)", bx + 4, by + 10.5,
                     badge.dark ? "#fff" : "#1d232b", escape(badge.text));
    bx += w + 3;
  }
  return o + "</g>";
}

/// The culled matter under a tree: greyed boxes with the reason.
std::string culledBoxes(const Material& m, int index, std::string_view view, double top, double width) {
  std::string o;
  double y = top;
  for (const auto& c : m.culled) {
    o += fmt::format(R"(<g class="culled" id="{}" data-culled="{}"><title>culled: {}</title>)",
                     escape(elementId(index, std::string(view) + "-culled", c.what)), escape(c.what), escape(c.why));
    o += fmt::format(R"(<rect x="{}" y="{:.1f}" width="{:.1f}" height="34" rx="6" fill="#eceff2" stroke="#aab3bd" )"
                     R"(stroke-dasharray="4 3"/>)",
                     kMargin, y, width - 2 * kMargin);
    o += fmt::format(R"(<text x="{}" y="{:.1f}" font-size="12" fill="#7b8794" font-weight="600">{} (culled)</text>)",
                     kMargin + 8, y + 14, escape(shortId(c.what)));
    const std::string why = c.why.size() > 90 ? c.why.substr(0, 89) + "\u2026" : c.why;
    o += fmt::format(R"(<text x="{}" y="{:.1f}" font-size="11" fill="#7b8794">{}</text></g>)", kMargin + 8, y + 28,
                     escape(why));
    y += 40;
  }
  return o;
}

/// The tree of `r` as an SVG diagram, with the culled matter under it when asked.
std::string treeSvg(int index, std::string_view view, const CompileResult& r, bool withCulled) {
  const Material& m = r.material;
  const TreeLayout L = layoutTree(m, r.tree);
  const double treeHeight = L.rows * kRowHeight;
  const double width = std::max(2 * kMargin + std::max(L.leaves, 1) * kSlotWidth, 560.0);
  const double height = 2 * kMargin + treeHeight + (withCulled ? 40.0 * static_cast<double>(m.culled.size()) : 0.0);
  auto centre = [&](int n) { return kMargin + L.x[n] * kSlotWidth + kSlotWidth / 2; };
  auto top = [&](int n) { return kMargin + L.depth[n] * kRowHeight; };
  std::string o = fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" class="tree" data-view="{}" width="{:.0f}" )"
                              R"(height="{:.0f}" viewBox="0 0 {:.0f} {:.0f}" role="img" aria-label="{} tree of {}">)",
                              view, width, height, width, height, view, escape(m.name));
  for (int n : r.tree.preorder)  // edges under the boxes
    for (int c : {m.nodes[n].left, m.nodes[n].right})
      if (c >= 0)
        o += fmt::format(R"(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="#9aa5b1" stroke-width="1.5"/>)",
                         centre(n), top(n) + kBoxHeight, centre(c), top(c));
  for (int n : r.tree.preorder) o += treeBox(index, view, r, n, centre(n), top(n));
  if (withCulled) o += culledBoxes(m, index, view, kMargin + treeHeight, width);
  return o + "</svg>";
}

// ----- The byte budget bar -----------------------------------------------------

/// One bar: the parts of `L` to scale against the budget line.
std::string byteBar(const std::string& caption, const StorageLayout& L, int budget, double scaleBytes) {
  const ByteBreakdown b = byteBreakdown(L);
  const std::array<int, 6> parts = {b.header, b.closureData, b.featureData, b.bases, b.padding, b.topLayer};
  constexpr double kWidth = 640, kLeft = 175, kBarHeight = 22;
  const double px = (kWidth - kLeft - 20) / std::max(scaleBytes * 8, 1.0);  // per bit
  std::string o = fmt::format(R"(<g class="bytebar"><text x="0" y="16" font-size="12">{}: {} B</text>)",
                              escape(caption), L.bytes());
  double x = kLeft;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i] == 0) continue;
    o += fmt::format(R"(<rect x="{:.2f}" y="2" width="{:.2f}" height="{}" fill="{}"><title>{}: {} bits</title></rect>)",
                     x, parts[i] * px, kBarHeight, kPartColours[i], kPartNames[i], parts[i]);
    x += parts[i] * px;
  }
  const double bx = kLeft + budget * 8 * px;
  o += fmt::format(R"(<line class="budget" x1="{:.2f}" y1="0" x2="{:.2f}" y2="{}" stroke="#c62828" stroke-width="2" )"
                   R"(stroke-dasharray="5 3"/>)",
                   bx, bx, kBarHeight + 4);
  return o + "</g>";
}

std::string byteSection(const MaterialPage& p) {
  const CompileResult& r = *p.result;
  const StorageLayout& before = p.authored ? p.authored->after : r.before;
  const double scale = std::max({static_cast<double>(r.budgetBytes), static_cast<double>(before.bytes()),
                                  static_cast<double>(r.after.bytes())});
  std::string o = "<h3>Byte budget</h3>";
  o += fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" class="budget" width="640" height="96" )"
                   R"(viewBox="0 0 640 96" role="img" aria-label="bytes per pixel against the budget of {} B">)",
                   r.budgetBytes);
  o += byteBar("authored", before, r.budgetBytes, scale);
  o += "<g transform=\"translate(0 34)\">" + byteBar("after simplification", r.after, r.budgetBytes, scale) + "</g>";
  o += fmt::format(R"(<text x="175" y="88" font-size="11" fill="#c62828">budget {} B per pixel (dashed line)</text>)",
                   r.budgetBytes);
  o += "</svg><table><tr><th>part</th><th>bits</th><th>bytes</th></tr>";
  const ByteBreakdown b = byteBreakdown(r.after);
  const std::array<int, 6> parts = {b.header, b.closureData, b.featureData, b.bases, b.padding, b.topLayer};
  for (std::size_t i = 0; i < parts.size(); ++i)
    o += fmt::format(R"(<tr><td><span class="badge" style="background:{};color:#fff">&#160;</span>{}</td>)"
                     R"(<td class="num">{}</td><td class="num">{:.2f}</td></tr>)",
                     kPartColours[i], kPartNames[i], parts[i], parts[i] / 8.0);
  return o + fmt::format(R"(<tr><th>total</th><td class="num">{}</td><td class="num">{}</td></tr></table>)", b.total(),
                         r.after.bytes());
}

// ----- Tables ------------------------------------------------------------------

std::string summaryList(const CompileResult& r, const std::optional<CompileResult>& authored) {
  const Material& m = r.material;
  std::uint16_t feats = 0;
  for (int s : r.tree.slabOrder) feats |= m.slabs[s].features;
  int shared = 0;
  for (const auto& b : m.bases) shared += b.slabs.size() > 1 ? 1 : 0;
  const StorageLayout& before = authored ? authored->after : r.before;
  std::string o = "<dl class=\"summary\">";
  auto row = [&](std::string_view k, const std::string& v) { o += fmt::format("<dt>{}</dt><dd>{}</dd>", k, v); };
  row("Budget", fmt::format("{} B per pixel, {} closures", r.budgetBytes, r.maxClosures));
  row("Authored", fmt::format("{} B, {} closures", before.bytes(), before.closures.size()));
  row("After simplification", fmt::format("{} B, {} closures", r.after.bytes(), r.after.closures.size()));
  row("Layout class", std::string(layoutClassName(r.after.layoutClass)));
  row("Blend mode", std::string(blendModeName(m.settings.blendMode)));
  const std::string list = featureList(feats);
  row("Features", list.empty() ? "none" : escape(list));
  row("Local bases", fmt::format("{} ({} shared by several slabs)", m.bases.size(), shared));
  return o + "</dl>";
}

/// A node id in a table, linked to its source line when the source is listed.
std::string nodeLink(const MaterialPage& p, int index, const std::string& id, const std::string& pointer) {
  const int line = lineOf(p, pointer);
  const std::string code = "<code>" + escape(id) + "</code>";
  return line > 0 ? fmt::format(R"(<a href="#{}">{}</a>)", sourceAnchor(index, line), code) : code;
}

std::string featureTable(const MaterialPage& p, int index, const CompileResult& r) {
  const Material& m = r.material;
  std::string o = "<h3>Feature lines</h3><table><tr><th>BSDF</th><th>node</th><th>features</th><th>SSS type</th>"
                  "<th>basis</th></tr>";
  for (std::size_t i = 0; i < r.tree.slabOrder.size(); ++i) {
    const Slab& s = m.slabs[r.tree.slabOrder[i]];
    std::string badges;
    for (int b = 0; b < kFeatureCount; ++b)
      if (s.features & (1u << b)) badges += fmt::format("<span class=\"badge\">{}</span>", featureName(b));
    const int node = r.tree.slabNode[r.tree.slabOrder[i]];
    o += fmt::format("<tr><td class=\"num\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>", i,
                     nodeLink(p, index, s.id, node >= 0 ? m.nodes[node].pointer : std::string()),
                     badges.empty() ? "none" : badges, sssTypeName(s.sssType), s.basis);
  }
  o += "</table>";
  if (m.bases.empty()) return o;
  o += "<h3>Local bases</h3><table><tr><th>basis</th><th>normal</th><th>tangent</th><th>slabs</th></tr>";
  for (std::size_t b = 0; b < m.bases.size(); ++b) {
    std::string slabs;
    for (int s : m.bases[b].slabs) slabs += (slabs.empty() ? "" : ", ") + escape(m.slabs[s].id);
    o += fmt::format("<tr><td class=\"num\">{}{}</td><td><code>{}</code></td><td><code>{}</code></td><td>{}</td></tr>",
                     b, m.bases[b].slabs.size() > 1 ? " (shared)" : "", escape(renderValue(m, m.bases[b].normal)),
                     m.bases[b].tangent != kNoValue ? escape(renderValue(m, m.bases[b].tangent)) : "&#8212;", slabs);
  }
  return o + "</table>";
}

std::string storageTable(const CompileResult& r) {
  std::string o = fmt::format("<h3>Storage layout ({})</h3><table><tr><th>field</th><th>bits</th><th>encoding</th></tr>",
                              layoutClassName(r.after.layoutClass));
  for (const auto& f : r.after.fields)
    o += fmt::format("<tr><td><code>{}</code></td><td class=\"num\">{}</td><td>{}</td></tr>", escape(f.name), f.bits,
                     escape(f.encoding));
  o += fmt::format("<tr><th>total</th><td class=\"num\">{}</td><td>packed into {} UINT32</td></tr>", r.after.totalBits,
                   r.after.words());
  if (r.after.layoutClass != LayoutClass::Volume)
    o += "<tr><td><code>top_layer</code></td><td class=\"num\">32</td>"
         "<td>octahedral normal 2 x unorm12 | roughness unorm8</td></tr>";
  return o + "</table>";
}

std::string blocksTable(const CompileResult& r) {
  if (r.blocks.empty()) return "";
  std::string o = "<h3>Building blocks</h3><table><tr><th>block</th><th>kind</th><th>expanded into</th></tr>";
  for (const auto& b : r.blocks) {
    std::string nodes;
    for (const auto& n : b.nodes) nodes += (nodes.empty() ? "" : ", ") + fmt::format("<code>{}</code>", escape(n));
    o += fmt::format("<tr><td><code>{}</code> <small>{}</small></td><td>{}</td><td>{}</td></tr>", escape(b.id),
                     escape(b.pointer), escape(b.kind), nodes.empty() ? "(its base)" : nodes);
  }
  return o + "</table>";
}

std::string stepsTable(const MaterialPage& p, int index) {
  const CompileResult& r = *p.result;
  std::string o = "<h3>Simplification</h3>";
  if (r.steps.empty()) o += "<p>No step: the material fits its budget.</p>";
  else {
    o += "<table><tr><th>step</th><th>action</th><th>node</th><th>depth</th><th>bytes</th><th>closures</th></tr>";
    for (std::size_t i = 0; i < r.steps.size(); ++i) {
      const SimplifyStep& s = r.steps[i];
      o += fmt::format("<tr><td class=\"num\">{}</td><td>{} {}</td><td><code>{}</code></td><td class=\"num\">{}</td>"
                       "<td class=\"num\">{} &#8594; {}</td><td class=\"num\">{} &#8594; {}</td></tr>",
                       i + 1, escape(s.action), escape(s.kind), escape(s.node), s.depth, s.bytesBefore, s.bytesAfter,
                       s.closuresBefore, s.closuresAfter);
    }
    o += "</table>";
  }
  if (!p.stepsNote.empty()) o += "<p>" + escape(p.stepsNote) + "</p>";
  if (p.steps.empty()) return o;
  o += "<h3>Simplification steps, measured</h3><table><tr><th>step</th><th>budget</th><th>bytes</th><th>closures</th>";
  for (const auto& c : p.stepColumns) o += "<th>" + escape(c) + "</th>";
  o += "</tr>";
  for (const auto& s : p.steps) {
    o += fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>",
                     escape(s.label), s.budget, s.bytes, s.closures);
    for (const auto& c : s.cells) o += "<td class=\"num\">" + escape(c) + "</td>";
    o += "</tr>";
  }
  o += "</table>";
  std::string previews;
  for (std::size_t i = 0; i < p.steps.size(); ++i) {
    const StepView& s = p.steps[i];
    if (s.png.empty()) continue;
    previews += fmt::format(R"(<figure id="m{}-preview-{}"><img alt="{} preview" src="data:image/png;base64,{}">)"
                            R"(<figcaption>{}: {} B, {} closures</figcaption></figure>)",
                            index, i, escape(s.label), base64(s.png), escape(s.label), s.bytes, s.closures);
  }
  if (!previews.empty()) o += "<div class=\"previews\">" + previews + "</div>";
  if (!p.errorPlotSvg.empty()) {
    std::string svg = p.errorPlotSvg;
    if (svg.rfind("<?xml", 0) == 0) svg.erase(0, svg.find("?>") + 2);
    o += "<figure class=\"plot\">" + svg + "</figure>";
  }
  return o;
}

// ----- Diagnostics and source ---------------------------------------------------

std::string_view severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}

std::string diagnosticsList(const MaterialPage& p, int index) {
  if (p.diagnostics.empty()) return "";
  const bool listed = !p.sourceText.empty() && p.sourceText.size() <= kMaxListedSource;
  std::string o = "<h3>Diagnostics</h3><ul class=\"diag\">";
  for (const Diagnostic& d : p.diagnostics) {
    std::string where = escape(d.file.empty() ? p.file : d.file);
    if (d.line > 0) {
      const std::string pos = fmt::format("{}:{}:{}", where, d.line, d.column);
      const bool here = listed && (d.file.empty() || d.file == p.file);
      where = here ? fmt::format(R"(<a href="#{}">{}</a>)", sourceAnchor(index, d.line), pos) : pos;
    }
    o += fmt::format(R"(<li class="{}"><span class="sev">{}</span>{}: {})", severityName(d.severity),
                     severityName(d.severity), where, escape(d.message));
    if (d.hasPointer) o += fmt::format(" <code class=\"pointer\">{}</code>", escape(d.pointer.empty() ? "/" : d.pointer));
    o += "</li>";
  }
  return o + "</ul>";
}

std::string sourceListing(const MaterialPage& p, int index) {
  if (p.sourceText.empty() || p.sourceText.size() > kMaxListedSource) return "";
  std::string o = "<details class=\"source\"><summary>Source</summary><pre class=\"source\">";
  int line = 1;
  std::size_t start = 0;
  while (start <= p.sourceText.size()) {
    std::size_t end = p.sourceText.find('\n', start);
    if (end == std::string::npos) end = p.sourceText.size();
    if (end == start && end == p.sourceText.size() && line > 1) break;  // the final newline
    o += fmt::format(R"(<span id="{}" data-line="{}">{}</span>)", sourceAnchor(index, line), line,
                     escape(std::string_view(p.sourceText).substr(start, end - start)));
    ++line;
    start = end + 1;
  }
  return o + "</pre></details>";
}

std::string materialSection(const MaterialPage& p, int index) {
  const std::string name = p.result ? p.result->material.name : p.file;
  std::string o = fmt::format(R"(<section class="material" id="m{}" data-material="{}"><h2>{}</h2>)", index,
                              escape(name), escape(name));
  o += fmt::format("<p><code>{}</code></p>", escape(p.file));
  o += diagnosticsList(p, index);
  if (!p.result) {
    o += "<p class=\"failed\">It did not load or compile: nothing to report but its diagnostics.</p>";
    return o + sourceListing(p, index) + "</section>";
  }
  const CompileResult& r = *p.result;
  o += summaryList(r, p.authored);
  o += byteSection(p);
  o += "<h3>Tree</h3><div class=\"trees\">";
  if (p.authored) {
    o += "<figure><figcaption>Authored</figcaption>" + treeSvg(index, "authored", *p.authored, true) + "</figure>";
    o += "<figure><figcaption>After simplification</figcaption>" + treeSvg(index, "simplified", r, false) + "</figure>";
  } else {
    o += "<figure><figcaption>Authored (it fits its budget: nothing simplified)</figcaption>" +
         treeSvg(index, "authored", r, true) + "</figure>";
  }
  o += "</div>";
  o += blocksTable(r) + featureTable(p, index, r) + stepsTable(p, index) + storageTable(r) + sourceListing(p, index);
  return o + "</section>";
}

// ----- The scene chart ----------------------------------------------------------

std::string sceneSection(const Page& page) {
  const SceneHeader& s = *page.scene;
  std::vector<std::pair<int, int>> bars;  // bytes, material index
  for (std::size_t i = 0; i < page.materials.size(); ++i)
    if (page.materials[i].result) bars.emplace_back(page.materials[i].result->after.bytes(), static_cast<int>(i));
  std::stable_sort(bars.begin(), bars.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  double most = s.budgetBytes;
  for (const auto& b : bars) most = std::max(most, static_cast<double>(b.first));
  constexpr double kLeft = 220, kWidth = 760, kRow = 22;
  const double px = (kWidth - kLeft - 60) / std::max(most, 1.0);
  const double height = 30 + kRow * static_cast<double>(bars.size());
  std::string o = fmt::format(R"(<section class="scene" id="scene"><h2>Scene {}</h2><p>Platform {}: {} B per pixel, )"
                              R"({} closures; {} materials.</p>)",
                              escape(s.name), s.platform.empty() ? "(none)" : escape(s.platform), s.budgetBytes,
                              s.maxClosures, page.materials.size());
  o += fmt::format(R"(<svg xmlns="http://www.w3.org/2000/svg" class="scene-chart" width="{}" height="{:.0f}" )"
                   R"(viewBox="0 0 {} {:.0f}" role="img" aria-label="bytes per pixel of every material">)",
                   kWidth, height, kWidth, height);
  for (std::size_t i = 0; i < bars.size(); ++i) {
    const auto& [bytes, m] = bars[i];
    const double y = 8 + kRow * static_cast<double>(i);
    const std::string name = page.materials[m].result->material.name;
    o += fmt::format(R"(<g class="scene-bar" data-material="{}"><text x="{}" y="{:.1f}" )"
                     R"(font-size="12" text-anchor="end">{}</text>)",
                     escape(name), kLeft - 8, y + 13, escape(shortId(name)));
    o += fmt::format(R"(<rect x="{}" y="{:.1f}" width="{:.2f}" height="16" fill="{}"/>)", kLeft, y + 1, bytes * px,
                     bytes > s.budgetBytes ? "#c62828" : "#2f6fde");
    o += fmt::format(R"(<text x="{:.2f}" y="{:.1f}" font-size="11">{} B</text></g>)", kLeft + bytes * px + 4, y + 13,
                     bytes);
  }
  const double bx = kLeft + s.budgetBytes * px;
  o += fmt::format(R"(<line class="budget" x1="{:.2f}" y1="0" x2="{:.2f}" y2="{:.0f}" stroke="#c62828" )"
                   R"(stroke-width="2" stroke-dasharray="5 3"/><text x="{:.2f}" y="{:.0f}" font-size="11" )"
                   R"(fill="#c62828" text-anchor="end">budget {} B</text></svg></section>)",
                   bx, bx, height - 12, bx - 4, height - 2, s.budgetBytes);
  return o;
}

}  // namespace

MaterialPage compiledMaterial(const std::string& file, const std::string& text, const CompileOptions& options,
                              std::string* messages) {
  MaterialPage p;
  p.file = file;
  p.sourceText = text;
  Diagnostics diags(file);
  p.result = compileText(file, text, options, diags);
  p.diagnostics = diags.all();
  p.locator = diags.locator();
  if (messages) *messages = diags.formatAll();
  if (p.result && !p.result->steps.empty()) {
    Diagnostics same(file);  // it compiled with a budget: it compiles without one, with the same diagnostics
    p.authored = compileText(file, text, unsimplifiedOptions(options), same);
  }
  return p;
}

ByteBreakdown byteBreakdown(const StorageLayout& L) {
  ByteBreakdown b;
  for (const auto& f : L.fields) {
    if (f.name == "header" || f.name.ends_with(".header")) b.header += f.bits;
    else if (f.basis >= 0) b.bases += f.bits;
    else if (f.feature != 0) b.featureData += f.bits;
    else b.closureData += f.bits;
  }
  b.padding = L.words() * 32 - L.totalBits;
  b.topLayer = (L.bytes() - L.words() * 4) * 8;
  return b;
}

std::string escape(std::string_view text) {
  std::string o;
  o.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k)
      v = (v << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) o += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return o;
}

std::string formatPage(const Page& page) {
  std::string o = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                  "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
                  "style-src 'unsafe-inline'; img-src data:\">"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
                  "<meta name=\"generator\" content=\"substratec\">";
  o += "<title>" + escape(page.title) + "</title><style>" + kStyle + "</style></head><body>";
  o += "<header class=\"page\"><h1>" + escape(page.title) + "</h1>";
  int failed = 0;
  for (const auto& m : page.materials) failed += m.result ? 0 : 1;
  o += fmt::format("<p>{} material{}{}. Generated by substratec.</p></header>", page.materials.size(),
                   page.materials.size() == 1 ? "" : "s", failed ? fmt::format(", {} did not compile", failed) : "");
  if (page.materials.size() > 1) {
    o += "<nav class=\"toc\">";
    for (std::size_t i = 0; i < page.materials.size(); ++i) {
      const auto& m = page.materials[i];
      o += fmt::format("<a href=\"#m{}\">{}</a>", i, escape(m.result ? m.result->material.name : m.file));
    }
    o += "</nav>";
  }
  o += "<main>";
  if (page.scene) o += sceneSection(page);
  for (std::size_t i = 0; i < page.materials.size(); ++i) o += materialSection(page.materials[i], static_cast<int>(i));
  return o + "</main></body></html>\n";
}

}  // namespace substratec::html
