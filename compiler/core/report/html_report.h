// The report as one self-contained HTML page for a person (`substratec report
// --html`, and `scene -o DIR`'s report.html): per material the tree as a
// diagram (authored beside simplified; features as badges, shared bases
// marked, culled matter greyed with the reason), the byte budget as a bar,
// the simplification steps (with previews and the sweep's rows and plot when
// the caller measured them), the storage layout and feature lines, and the
// diagnostics linked to the source line their pointer names; for a scene, a
// sorted bar chart of every material against the platform's budget.
//
// The page is data only: inline CSS, inline SVG and PNG data URIs, no script,
// and a Content-Security-Policy that forbids fetching anything, so it opens
// from disk offline and looks the same everywhere. Formatting only: the
// caller compiles, renders and measures (docs/report.md, "HTML").
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"

namespace substratec::html {

/// One row of the simplification steps a caller measured (report --previews,
/// --sweep): the material compiled at that step, an optional preview image
/// and the sweep's cells for `MaterialPage::stepColumns`.
struct StepView {
  std::string label;  // "authored", "full budget", "step 2", "full simplification"
  int budget = 0, bytes = 0, closures = 0;
  std::string png;                 // an encoded PNG ("" when no preview was asked for)
  std::vector<std::string> cells;  // one per MaterialPage::stepColumns
};

/// One material of the page.
struct MaterialPage {
  std::string file;        // what diagnostics call it (the display name)
  std::string sourceText;  // the substrate-material/1 text compiled, listed with line anchors ("" for none)
  std::shared_ptr<const SourceLocator> locator;  // of sourceText: pointers become line links (may be null)
  std::vector<Diagnostic> diagnostics;           // of this material's compile (and import)
  std::optional<CompileResult> result;           // nullopt: it did not compile (its errors are shown)
  std::optional<CompileResult> authored;         // unsimplified, when simplification changed it
  std::vector<StepView> steps;                   // measured steps (empty: none asked for)
  std::vector<std::string> stepColumns;          // the sweep's column names ("rel_mse", ...)
  std::string errorPlotSvg;                      // the sweep's error-against-cost plot ("" for none)
  std::string stepsNote;                         // why there are no measured steps, when asked for but none
};

/// A material's part of the page, compiled from `text` (named `file` in its
/// diagnostics) with `options`, and again unsimplified (pipeline's
/// unsimplifiedOptions) when its budget simplified it; its diagnostics and
/// their locator kept. `messages`, when given, receives the diagnostics as
/// they print (Diagnostics::formatAll). What `report --html`, `scene` and the
/// tests build a page from.
MaterialPage compiledMaterial(const std::string& file, const std::string& text, const CompileOptions& options,
                              std::string* messages = nullptr);

/// A scene page's header: its name, platform and budget; every material of
/// the page is one of its materials.
struct SceneHeader {
  std::string name;
  std::string platform;  // "" for none
  int budgetBytes = 0, maxClosures = 0;
};

struct Page {
  std::string title;
  std::optional<SceneHeader> scene;
  std::vector<MaterialPage> materials;
};

/// The whole page. Deterministic: the same page gives the same bytes.
std::string formatPage(const Page& page);

/// What the byte bar is made of: the bits of `L` by kind (header, closure
/// data, feature data, shared bases, padding of the last word, top layer),
/// which sum to L.bytes() * 8.
struct ByteBreakdown {
  int header = 0, closureData = 0, featureData = 0, bases = 0, padding = 0, topLayer = 0;
  int total() const { return header + closureData + featureData + bases + padding + topLayer; }
};
ByteBreakdown byteBreakdown(const StorageLayout& L);

/// `text` escaped for HTML text and attribute values.
std::string escape(std::string_view text);

/// RFC 4648 base64 of `bytes` (for data: URIs).
std::string base64(std::string_view bytes);

}  // namespace substratec::html
