// How the command line states and checks its numbers: a range with its unit
// in --help (`--budget INT:in [8, 1024] bytes`), and errors that say what is wrong —
// "'abc' is not a number", "'2.5' is not a whole number", "'1e40' is out of
// range [0, 1e+30]" — with bounds printed as written ({fmt}'s shortest form,
// never `1000000000000000019884624838656.000000`). Integers are decimal only
// (CLI11 alone would read `010` as octal 8).
#pragma once
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <type_traits>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "diag/diagnostics.h"

namespace substratec::cli {

/// A number in [lo, hi] (inclusive) of type T; `unit` follows the range in
/// --help. Use it with ->transform (not ->check, whose validators may not
/// rewrite the value): an integer is handed on in its decimal form.
template <typename T>
CLI::Validator inRange(T lo, T hi, const std::string& unit = "") {
  const std::string description = fmt::format("in [{}, {}]{}", lo, hi, unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [lo, hi](std::string& input) -> std::string {
        const std::string shown = quoteForDiagnostic(input, 32);
        // Any number at all (strtod: decimal, exponent, inf, nan)?
        char* end = nullptr;
        const double asDouble = input.empty() ? 0.0 : std::strtod(input.c_str(), &end);
        (void)asDouble;
        const bool number = !input.empty() && end == input.c_str() + input.size();
        if (!number) return fmt::format("{} is not a number", shown);
        const std::string range = fmt::format("[{}, {}]", lo, hi);
        if constexpr (std::is_integral_v<T>) {
          T value{};
          const char* first = input.c_str();
          const char* last = first + input.size();
          if (*first == '+') ++first;
          const auto [ptr, ec] = std::from_chars(first, last, value);
          if (ec == std::errc() && ptr == last) {
            if (value < lo || value > hi) return fmt::format("{} is out of range {}", shown, range);
            input = std::to_string(value);  // CLI11 converts it again: decimal, as checked
            return "";
          }
          // Digits that do not fit T (too large, or negative for an unsigned T).
          const char* digits = input.c_str() + (input[0] == '-' || input[0] == '+' ? 1 : 0);
          const bool whole = *digits && std::all_of(digits, last, [](char c) { return c >= '0' && c <= '9'; });
          if (whole) return fmt::format("{} is out of range {}", shown, range);
          return fmt::format("{} is not a whole number in {}", shown, range);
        } else {
          if (!(asDouble >= static_cast<double>(lo) && asDouble <= static_cast<double>(hi)))
            return fmt::format("{} is out of range {}", shown, range);
          return "";
        }
      },
      description);
}

}  // namespace substratec::cli
