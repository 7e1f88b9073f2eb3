#include "emit/layout_json.h"

namespace substratec {

nlohmann::ordered_json layoutJson(const Material& m, const StorageLayout& L) {
  using J = nlohmann::ordered_json;
  J j;
  j["format"] = "substrate-layout/1";
  j["material"] = m.name;
  j["layout"] = std::string(layoutClassName(L.layoutClass));
  j["closures"] = L.closures.size();
  j["bases"] = L.basisCount;
  j["words"] = L.words();
  j["bits"] = L.totalBits;
  j["bytes_per_pixel"] = L.bytes();
  j["render_target_words"] = std::min(L.words(), 3);
  J fields = J::array();
  int offset = 0;
  for (const auto& f : L.fields) {
    J e = {{"name", f.name}, {"offset", offset}, {"bits", f.bits}, {"word", offset / 32},
           {"shift", offset % 32}, {"encoding", f.encoding}};
    if (f.closure >= 0) e["closure"] = f.closure;
    if (f.basis >= 0) e["basis"] = f.basis;
    fields.push_back(e);
    offset += f.bits;
  }
  j["fields"] = fields;
  if (L.layoutClass == LayoutClass::Volume)  // a volume has no surface: no top layer
    j["top_layer"] = {{"bits", 0}, {"fields", J::array()}};
  else
    j["top_layer"] = {{"bits", 32},
                    {"fields", J::array({J{{"name", "normal"}, {"offset", 0}, {"bits", 24}, {"encoding", "octahedral 2 x unorm12"}},
                                         J{{"name", "roughness"}, {"offset", 24}, {"bits", 8}, {"encoding", "unorm8"}}})}};
  J closures = J::array();
  for (std::size_t i = 0; i < L.closures.size(); ++i) {
    const ClosureLayout& c = L.closures[i];
    closures.push_back({{"closure", i}, {"node", m.slabs[c.slab].id}, {"basis", c.basis}, {"is_top", c.isTop},
                        {"weight", c.storesWeight}, {"coverage_above", c.storesCoverageAbove}});
  }
  j["closure_list"] = closures;
  return j;
}

}  // namespace substratec
