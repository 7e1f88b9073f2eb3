// `<name>.layout.json`: the packing layout of one material (words, bit
// fields with their offsets and encodings, closures, bytes), schema
// schema/substrate-layout.schema.json.
#pragma once
#include <nlohmann/json.hpp>

#include "ir/material.h"
#include "storage/layout.h"

namespace substratec {

nlohmann::ordered_json layoutJson(const Material& m, const StorageLayout& layout);

}  // namespace substratec
