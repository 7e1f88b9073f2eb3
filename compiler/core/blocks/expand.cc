#include "blocks/expand.h"

#include <algorithm>

#include <fmt/format.h>

#include "blocks/blocks.h"

namespace substratec::blocks {

namespace {

const BuildingBlock* blockOf(const Json& j) {
  if (!j.is_object()) return nullptr;
  auto k = j.find("kind");
  return k != j.end() && k->is_string() ? findBuildingBlock(k->get_ref<const std::string&>()) : nullptr;
}

/// True when `j` or anything in it is a building block. Recursion is bounded
/// by the reader's nesting limit.
bool containsBlock(const Json& j) {
  if (blockOf(j)) return true;
  if (j.is_object() || j.is_array())
    for (const Json& e : j)
      if (containsBlock(e)) return true;
  return false;
}

/// Collects the nodes a block's unit names, under "<prefix>_<part>".
class ExpansionWriter final : public NodeWriter {
 public:
  ExpansionWriter(NameSet& names, std::string prefix, Json& inputs)
      : names_(names), prefix_(std::move(prefix)), inputs_(inputs) {}
  Value node(std::string_view wantedId, Json body) override {
    std::string id = names_.claim(sanitizeIdentifier(prefix_ + "_" + std::string(wantedId)));
    nodes_.emplace_back(id, std::move(body));
    return id;
  }
  /// An input "<prefix>_presence" of 0, as an importer keeps a source's
  /// invisible material: it keeps its matter, and its coverage can be raised.
  Value invisiblePresence() override {
    const std::string id = names_.claim(sanitizeIdentifier(prefix_ + "_presence"));
    inputs_[id] = Json{{"type", "float"}, {"default", 0}, {"min", 0}, {"max", 1},
                       {"description", "the presence of a block whose opacity is 0 (an input, so that the material "
                                       "keeps its matter)"}};
    return "$" + id;
  }
  std::vector<std::pair<std::string, Json>>& nodes() { return nodes_; }

 private:
  NameSet& names_;
  std::string prefix_;
  Json& inputs_;
  std::vector<std::pair<std::string, Json>> nodes_;
};

class Expander {
 public:
  Expander(const Json& doc, const ResolveLimits& limits, std::vector<ExpandedBlock>& expanded, Diagnostics& diags)
      : doc_(doc), limits_(limits), expanded_(expanded), diags_(diags) {
    names_.insert(doc.value("name", std::string()));
    if (auto in = doc.find("inputs"); in != doc.end() && in->is_object())
      for (auto it = in->begin(); it != in->end(); ++it) names_.insert(it.key());
    for (auto it = doc["nodes"].begin(); it != doc["nodes"].end(); ++it) names_.insert(it.key());
  }

  /// The document's nodes, expanded, in order.
  Json run(const Json& nodes) {
    for (auto it = nodes.begin(); it != nodes.end(); ++it) {
      const std::string ptr = "/nodes/" + pointerToken(it.key());
      Json body = *it;
      if (const BuildingBlock* b = blockOf(body)) {
        const std::size_t record = expanded_.size();
        Value root = expand(*b, body, it.key(), ptr);
        if (!(root.is_string() && takeRoot(root.get<std::string>(), it.key(), record, body)))
          body = Json{{"kind", "coverage_weight"}, {"a", std::move(root)}, {"weight", 1}};  // a pin as given
      } else {
        expandInline(body, it.key(), ptr);
      }
      out_[it.key()] = std::move(body);
    }
    return std::move(out_);
  }

  bool overLimit() const { return expansions_ > limits_.maxNodes; }
  /// The inputs the expansions added (invisible presences).
  const Json& addedInputs() const { return inputs_; }

 private:
  /// Expands block `body` (its unit's nodes, expanded in turn, go to out_);
  /// returns its root.
  Value expand(const BuildingBlock& b, const Json& body, const std::string& id, const std::string& ptr) {
    if (++expansions_ > limits_.maxNodes) return Value(id);  // reported by the caller
    ExpansionWriter w(names_, id, inputs_);
    BlockContext context{w, doc_, {}};
    Value root = b.expand(body, context);
    for (const std::string& warning : context.warnings) diags_.warning(ptr, fmt::format("{}: {}", b.signature.kind, warning));
    const std::size_t record = expanded_.size();
    expanded_.push_back({id, b.signature.kind, ptr, {}});
    for (auto& [nodeId, nodeBody] : w.nodes()) {
      expandInline(nodeBody, nodeId, ptr);  // a block given inline as a pin (a coated_layer's base)
      expanded_[record].nodes.push_back(nodeId);
      out_[nodeId] = std::move(nodeBody);
    }
    return root;
  }

  /// When `root` is a node of expanded_[record], it is renamed `id` (its body
  /// moved into `body`); false otherwise. Nothing refers to it by its old
  /// name: it is the top of its expansion, and the name was new.
  bool takeRoot(const std::string& root, const std::string& id, std::size_t record, Json& body) {
    if (record >= expanded_.size()) return false;
    auto& nodes = expanded_[record].nodes;
    auto it = out_.find(root);
    if (it == out_.end() || std::find(nodes.begin(), nodes.end(), root) == nodes.end()) return false;
    body = std::move(*it);
    out_.erase(it);
    std::replace(nodes.begin(), nodes.end(), root, id);
    return true;
  }

  /// Every inline block inside `j` (a node of id `owner`) replaced by a
  /// reference to its root.
  void expandInline(Json& j, const std::string& owner, const std::string& ptr) {
    if (!j.is_object()) return;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!it->is_object()) continue;
      const std::string name = owner + "_" + it.key();
      const std::string p = ptr + "/" + pointerToken(it.key());
      if (const BuildingBlock* b = blockOf(*it))
        *it = expand(*b, *it, name, p);
      else
        expandInline(*it, name, p);
    }
  }

  const Json& doc_;
  const ResolveLimits& limits_;
  std::vector<ExpandedBlock>& expanded_;
  Diagnostics& diags_;
  NameSet names_;
  Json out_ = Json::object();
  Json inputs_ = Json::object();
  std::size_t expansions_ = 0;
};

}  // namespace

bool hasBuildingBlocks(const Json& doc) {
  auto nodes = doc.is_object() ? doc.find("nodes") : doc.end();
  return doc.is_object() && nodes != doc.end() && containsBlock(*nodes);
}

std::optional<Json> expandBuildingBlocks(const Json& doc, Diagnostics& diags, const ResolveLimits& limits,
                                         std::vector<ExpandedBlock>& expanded) {
  ResolveLimits checking = limits;
  checking.blocks = &blockSignatures();
  if (!resolveDocument(doc, diags, checking)) return std::nullopt;
  Expander expander(doc, limits, expanded, diags);
  Json out = Json::object();  // the document's members in order, its nodes expanded
  for (auto it = doc.begin(); it != doc.end(); ++it) out[it.key()] = it.key() == "nodes" ? Json() : *it;
  out["nodes"] = expander.run(doc["nodes"]);
  if (!expander.addedInputs().empty()) {
    if (!out.contains("inputs") || !out["inputs"].is_object()) out["inputs"] = Json::object();
    for (const auto& [name, input] : expander.addedInputs().items()) out["inputs"][name] = input;
  }
  // What the resolve and the later passes say of an expansion's nodes is said
  // at the block the author wrote.
  for (const ExpandedBlock& b : expanded)
    for (const std::string& node : b.nodes)
      diags.mapPointers("/nodes/" + pointerToken(node), b.pointer,
                        fmt::format("in what {} {} expands into", b.kind, quoteForDiagnostic(b.id)));
  if (expander.overLimit()) {
    diags.error("/nodes", fmt::format("the building blocks expand more than {} times (the node-count limit)",
                                      limits.maxNodes));
    return std::nullopt;
  }
  return out;
}

}  // namespace substratec::blocks
