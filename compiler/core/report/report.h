// The report for technical artists (text) and tools (JSON): budget, bytes
// and closures before/after simplification, layout class, shared bases, the
// tree dump grouped by distance from leaves, one feature line per BSDF, what
// was culled and why, and the simplification steps. docs/report.md
// documents the JSON.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/pipeline.h"

namespace substratec {

std::string formatReportText(const CompileResult& r);
nlohmann::ordered_json reportJson(const CompileResult& r);

}  // namespace substratec
