// MaterialX values as Substrate values: a shading node's inputs, followed
// through `nodename`, `nodegraph`/`output` and `interfacename` connections
// (into node graphs, and into the node graph implementing a document's own
// `nodedef`), each MaterialX node written as a named value node:
//   image, tiledimage, gltf_image, gltf_colorimage, gltf_normalmap -> a texture
//     input named after the image file, sampled at its texcoord (tiling,
//     offset, place2d and the gltf transforms as uv arithmetic);
//   the math nodes (add, multiply, mix, clamp, power, dotproduct, invert,
//     remap, ...), convert/combine/extract/separate, normalmap, luminance,
//     hsvtorgb, texcoord, position, geometric normal/tangent -> value nodes;
//   nodes without a value node (rgbtohsv, trigonometry, conditionals, ...):
//     evaluated at import when their inputs are constants (a warning when that
//     freezes an input), and procedural noises (or such nodes on varying
//     inputs) replaced by a texture input to bake them into (a warning);
//   the hair helpers (chiang_hair_roughness, chiang_hair_absorption_from_color,
//     deon_hair_absorption_from_melanin; mtlx_hair.h): evaluated at import
//     when their inputs are constants, else value nodes where the format has
//     the operations, else an error (a logarithm of what varies);
//   anything else: an error naming the node and its line.
// Values the document gives on a shading node or a node graph's interface
// become material inputs named after them (docs/import.md, "MaterialX").
#pragma once
#include <map>
#include <set>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "blocks/material_writer.h"
#include "blocks/surface_params.h"
#include "import/mtlx_document.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

class MtlxValues {
 public:
  MtlxValues(const MtlxDocument& doc, MaterialWriter& w, Diagnostics& d, std::string materialLabel)
      : doc_(doc), w_(w), d_(d), label_(std::move(materialLabel)) {}

  /// The shading node's `name` input of MaterialX type `type`: what it
  /// connects to, its value, or `def` when the document does not give it.
  Value param(pugi::xml_node shader, const std::string& name, const std::string& type,
              const std::vector<double>& def, ParamKind kind = ParamKind::Plain);
  /// The input's value as a number at import (nullopt when it is connected to
  /// something that varies); `def` when not given. For static settings
  /// (alpha_mode, thin_walled, rotations).
  std::optional<std::vector<double>> constant(pugi::xml_node shader, const std::string& name, const std::string& type,
                                              const std::vector<double>& def);
  /// True when the document sets or connects the input.
  bool given(pugi::xml_node shader, const std::string& name) const;
  /// Input `name` of a node inside a graph as the graph reads it (its value a
  /// literal, not a material input as param() makes a shading node's).
  Value value(pugi::xml_node node, const std::string& name, const std::string& type, const std::vector<double>& def);
  /// The node input `name` of `node` reads with `nodename` (in its scope; not
  /// a node graph), and which of its outputs; a null node otherwise.
  std::pair<pugi::xml_node, std::string> upstream(pugi::xml_node node, const std::string& name) const;
  /// Material inputs read at their values so far (by constant(), by frozen
  /// folds): a count, and the names read since a count (each once, in order).
  std::size_t frozenReads() const { return frozenNames_.size(); }
  std::vector<std::string> frozenInputsSince(std::size_t count) const;

  void warn(pugi::xml_node at, const std::string& what);
  void error(pugi::xml_node at, const std::string& what);
  bool ok() const { return ok_; }

  /// Enters the node graph implementing a document nodedef for `instance`:
  /// interface names inside it read the instance's inputs.
  struct Binding {
    pugi::xml_node instance, nodedef, graph;
  };
  void pushBinding(const Binding& b) { bindings_.push_back(b); }
  void popBinding() { bindings_.pop_back(); }
  /// The node graph (and nodedef) implementing node kind `kind`, if the document has one.
  std::optional<Binding> implementation(pugi::xml_node instance) const;
  /// The element `nodename` refers to from an input of `user`.
  pugi::xml_node resolveNodeName(pugi::xml_node user, const std::string& name) const;
  /// The node an `<output>` of a node graph reads, and which of its outputs.
  std::pair<pugi::xml_node, std::string> resolveGraphOutput(pugi::xml_node graph, const std::string& output,
                                                            pugi::xml_node at);

 private:
  struct Typed {
    Value v;
    std::string type;
  };
  Typed inputOf(pugi::xml_node node, const std::string& name, const std::string& type, const std::vector<double>& def,
                bool frozen, int depth);
  /// The input as declared (its own type), before inputOf fits it to `type`.
  Typed declaredInput(pugi::xml_node node, const std::string& name, const std::string& type,
                      const std::vector<double>& def, bool frozen, int depth);
  Typed connection(pugi::xml_node input, const std::string& type, bool frozen, int depth, bool* connected);
  Typed nodeValue(pugi::xml_node node, const std::string& output, bool frozen, int depth);
  Typed compute(pugi::xml_node node, const std::string& kind, const std::string& type, const std::string& output,
                bool frozen, int depth);
  /// One node's computation; its rules (per node kind) are members (mtlx_graph.cc).
  struct Call;
  Typed bake(pugi::xml_node node, const std::string& kind, const std::string& type, const std::string& why);
  Value textureOf(pugi::xml_node node, const std::string& file, bool srgb, const std::string& wrapU = "repeat",
                  const std::string& wrapV = "repeat");
  Value sampleOf(const Value& texture, const Value& uv);
  Value interfaceInput(pugi::xml_node graphInput, const std::string& name, const std::string& type);
  Value valueInput(const std::string& name, const std::string& type, const std::vector<double>& v,
                   const std::string& what);

  const MtlxDocument& doc_;
  MaterialWriter& w_;
  Diagnostics& d_;
  std::string label_;
  bool ok_ = true;
  std::vector<Binding> bindings_;
  std::map<std::string, Typed> memo_;       // node + output + mode + binding -> value
  std::set<std::string> active_;            // nodes being evaluated (cycles)
  std::map<std::string, Value> textures_;   // file + colour space -> "$input"
  std::map<std::string, Value> samples_;    // input + uv -> sample node
  std::map<std::string, Value> interface_;  // graph input -> "$input"
  std::set<std::string> warned_;
  std::vector<std::string> frozenNames_;  // interface inputs read at their values (frozen evaluation), one per read
};

/// A MaterialX value (`type` components) as a literal; colours given in
/// `srgb_texture` are decoded to linear.
Value mtlxLiteral(const std::vector<double>& v, const std::string& type, const std::string& colorspace);

}  // namespace substratec::import
