// Reading a MaterialX document (https://materialx.org, version 1.38/1.39)
// with pugixml: the XML parsed (syntax errors at file:line:col), XInclude
// (`<xi:include href=...>`) resolved relative to the including file (depth
// and count limited; a cycle, found by file identity whatever the spelling,
// is an error at the include that closes it, in the file that holds it), the top-level elements indexed by name,
// and every element locatable as `line N` of its file plus its element path
// (`nodegraph 'NG_brass1' / tiledimage 'image_color'`). Values are parsed from
// MaterialX's comma-separated strings.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pugixml.hpp>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "output/file_identity.h"

namespace substratec::import {

class MtlxDocument {
 public:
  /// Parses `text` (from `fileName`) and its includes. False with diagnostics.
  bool load(const std::string& text, const std::string& fileName, const std::string& baseDir,
            const ReadLimits& limits, Diagnostics& diags);

  /// Top-level elements (includes first, in order), and the one named `name`.
  const std::vector<pugi::xml_node>& topLevel() const { return top_; }
  pugi::xml_node find(const std::string& name) const;
  /// `fileprefix` in effect at `n` (its own, its ancestors', its document's).
  std::string filePrefix(pugi::xml_node n) const;

  /// Line and column of `n` in the main file (for an element of an included
  /// file: of the xi:include that brought it).
  void lineColumn(pugi::xml_node n, int& line, int& column) const;
  /// "tiledimage 'image_color' in nodegraph 'NG_brass1'" (+ " (included file.mtlx line N)").
  std::string describe(pugi::xml_node n) const;

 private:
  struct Loaded {
    std::string fileName, text;
    pugi::xml_document doc;
    int includeLine = 0, includeColumn = 0;  // of the xi:include in the main file (0 for the main file)
  };
  /// A file being read: what it is (device and inode, when it is a file),
  /// its path as read, and as diagnostics name it (relative to the main file
  /// as the user gave it).
  struct Reading {
    std::optional<FileId> id;
    std::string path, display;
  };
  bool loadOne(const std::string& text, const std::string& fileName, const Reading& reading, const std::string& dir,
               int depth, int includeLine, int includeColumn, const ReadLimits& limits, Diagnostics& diags);
  bool loadInclude(pugi::xml_node n, const Loaded& self, const Reading& reading, const std::string& dir, int depth,
                   int includeLine, int includeColumn, const ReadLimits& limits, Diagnostics& diags);
  const Loaded* owner(pugi::xml_node n) const;

  std::vector<std::unique_ptr<Loaded>> docs_;
  std::vector<pugi::xml_node> top_;
  std::map<std::string, pugi::xml_node> byName_;
  std::vector<Reading> loading_;  // the include stack, for cycles
};

/// The numbers of a MaterialX value string ("0.8, 0.8, 0.8"; "1"; "true" is
/// 1); nullopt when it is not a list of numbers.
std::optional<std::vector<double>> parseMtlxNumbers(const std::string& s);

/// Components of a MaterialX type (float 1, vector2 2, color3/vector3 3,
/// color4/vector4 4, integer/boolean 1), 0 for the others.
int mtlxComponents(const std::string& type);

}  // namespace substratec::import
