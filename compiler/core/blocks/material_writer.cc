#include "blocks/material_writer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "passes/resolve.h"

namespace substratec::blocks {

namespace {
/// The longest description written (the format's string limit is 64 KiB).
constexpr std::size_t kMaxDescription = 4096;
}  // namespace

std::string sanitizeIdentifier(std::string_view s, std::string_view prefix) {
  std::string out;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    if (ok) out += c;
    else if (!out.empty() && out.back() != '_') out += '_';  // no leading '_', no "__"
    if (out.size() > 2 * kMaxSanitizedIdentifier) break;      // the rest would be cut anyway
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (out.empty()) return out;
  if ((out[0] >= '0' && out[0] <= '9') || hasReservedPrefix(out) || isReservedWord(out))
    out = std::string(prefix) + "_" + out;
  if (out.size() > kMaxSanitizedIdentifier) out.resize(kMaxSanitizedIdentifier);
  while (!out.empty() && out.back() == '_') out.pop_back();
  // By construction usable; a prefix that is not would be the caller's bug.
  return isUsableIdentifier(out) ? out : std::string();
}

std::string NameSet::key(const std::string& s) const {
  if (!caseInsensitive_) return s;
  std::string k = s;
  for (char& c : k)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return k;
}

std::string NameSet::claim(const std::string& base) {
  if (!contains(base)) {
    insert(base);
    return base;
  }
  std::size_t& k = next_[key(base)];
  if (k < 2) k = 2;
  for (std::size_t tries = 0; tries < maxTries_; ++tries, ++k) {
    const std::string suffix = "_" + std::to_string(k);
    std::string stem = base.substr(0, std::min(base.size(), 128 - suffix.size()));
    while (!stem.empty() && stem.back() == '_') stem.pop_back();
    const std::string id = stem + suffix;
    if (!contains(id)) {
      insert(id);
      ++k;
      return id;
    }
  }
  throw std::length_error(fmt::format("no free name like \"{}\" after {} tries", base, maxTries_));
}

std::string uniqueMaterialName(NameSet& used, std::string_view wanted, const std::string& fallback) {
  std::string base = sanitizeIdentifier(wanted);
  if (base.empty()) base = fallback;
  return used.claim(base);
}

std::string descriptionText(std::string_view s, std::size_t maxBytes) {
  std::string out;
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    // The length of the UTF-8 sequence at i (RFC 3629: no overlong forms, no
    // surrogates, at most U+10FFFF), 0 when the bytes are not one.
    std::size_t n = 0;
    if (c >= 0x20 && c < 0x7f) n = 1;
    else if (c >= 0xc2 && c <= 0xdf) n = 2;
    else if (c >= 0xe0 && c <= 0xef) n = 3;
    else if (c >= 0xf0 && c <= 0xf4) n = 4;
    if (n > 1) {
      if (i + n > s.size()) n = 0;
      for (std::size_t j = 1; n && j < n; ++j)
        if ((static_cast<unsigned char>(s[i + j]) & 0xc0) != 0x80) n = 0;
      if (n) {
        const auto c1 = static_cast<unsigned char>(s[i + 1]);
        if ((c == 0xe0 && c1 < 0xa0) || (c == 0xed && c1 >= 0xa0) || (c == 0xf0 && c1 < 0x90) || (c == 0xf4 && c1 >= 0x90))
          n = 0;
      }
    }
    const std::string piece = n ? std::string(s.substr(i, n)) : fmt::format("\\x{:02x}", c);
    if (out.size() + piece.size() > maxBytes) {
      out += "...";
      break;
    }
    out += piece;
    i += n ? n : 1;
  }
  return out;
}

std::string quoteForDescription(std::string_view s, std::size_t maxBytes) {
  return "\"" + descriptionText(s, maxBytes) + "\"";
}

MaterialWriter::MaterialWriter(const std::string& name) : name_(name) { used_.insert(name_); }

std::string MaterialWriter::uniqueId(std::string_view wanted) {
  std::string base = sanitizeIdentifier(wanted);
  if (base.empty()) base = "value";
  return used_.claim(base);
}

Value MaterialWriter::addInput(std::string_view name, Json body) {
  std::string id = uniqueId(name);
  if (auto d = body.find("description"); d != body.end()) *d = descriptionText(d->get<std::string>(), kMaxDescription);
  inputs_[id] = std::move(body);
  return "$" + id;
}

Value MaterialWriter::describedInput(std::string_view name, Json body, const std::string& description) {
  if (!description.empty()) body["description"] = description;
  return addInput(name, std::move(body));
}

Value MaterialWriter::floatInput(std::string_view name, double value, std::optional<double> lo,
                                 std::optional<double> hi, const std::string& description) {
  Json b = {{"type", "float"}, {"default", value}};
  if (lo) b["min"] = *lo;
  if (hi) b["max"] = *hi;
  return describedInput(name, std::move(b), description);
}

Value MaterialWriter::colorInput(std::string_view name, const std::vector<double>& rgb, const std::string& description) {
  Json b = {{"type", "color"}, {"default", literal(rgb)}};
  return describedInput(name, std::move(b), description);
}

Value MaterialWriter::vec2Input(std::string_view name, double x, double y, const std::string& description) {
  Json b = {{"type", "vec2"}, {"default", Json::array({x, y})}};
  return describedInput(name, std::move(b), description);
}

Value MaterialWriter::vec3Input(std::string_view name, const std::vector<double>& xyz, const std::string& description) {
  Json b = {{"type", "vec3"}, {"default", literal(xyz)}};
  return describedInput(name, std::move(b), description);
}

Value MaterialWriter::textureInput(std::string_view name, bool srgb, const std::string& description,
                                   const std::string& file, const std::string& wrapU, const std::string& wrapV,
                                   bool nearest) {
  Json b = {{"type", "texture2d"}, {"colorspace", srgb ? "srgb" : "linear"}};
  if (!file.empty()) b["file"] = file;
  if (wrapU != "repeat" || wrapV != "repeat") b["wrap"] = wrapU == wrapV ? Json(wrapU) : Json::array({wrapU, wrapV});
  if (nearest) b["filter"] = "nearest";
  return describedInput(name, std::move(b), description);
}

Value MaterialWriter::node(std::string_view wantedId, Json body) {
  std::string id = uniqueId(wantedId);
  nodes_[id] = std::move(body);
  return id;
}

Value MaterialWriter::invisiblePresence() {
  return floatInput("presence", 0.0, 0.0, 1.0,
                    "the source's opacity, 0: a fully transparent surface (an input, not a constant, so that the "
                    "material keeps its matter)");
}

std::string MaterialWriter::text() const {
  Json doc = Json::object();
  doc["format"] = "substrate-material/1";
  doc["name"] = name_;
  if (!description_.empty()) doc["description"] = descriptionText(description_, kMaxDescription);
  if (!settings_.empty()) doc["settings"] = settings_;
  // Inputs no node reads are left out (a parameter the mapping did not need
  // would still cost a uniform).
  std::set<std::string> read;
  std::vector<const Json*> stack = {&nodes_};
  while (!stack.empty()) {
    const Json* j = stack.back();
    stack.pop_back();
    if (j->is_string() && j->get_ref<const std::string&>().rfind('$', 0) == 0) read.insert(j->get<std::string>().substr(1));
    if (j->is_structured())
      for (const auto& c : *j) stack.push_back(&c);
  }
  Json inputs = Json::object();
  for (const auto& [name, body] : inputs_.items())
    if (read.count(name)) inputs[name] = body;
  if (!inputs.empty()) doc["inputs"] = inputs;
  doc["nodes"] = nodes_;
  doc["output"] = output_;
  // Every string is valid UTF-8 by now (names are ASCII, descriptions went
  // through descriptionText); replacing what is not is only a safety net.
  return doc.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

// ---------------------------------------------------------------------------

bool isNull(const Value& v) { return v.is_null(); }

std::optional<std::vector<double>> literalOf(const Value& v) {
  if (v.is_number()) return std::vector<double>{v.get<double>()};
  if (!v.is_array() || v.empty()) return std::nullopt;
  std::vector<double> c;
  for (const auto& x : v) {
    if (!x.is_number()) return std::nullopt;
    c.push_back(x.get<double>());
  }
  return c;
}

bool isLiteral(const Value& v, double x) {
  auto c = literalOf(v);
  if (!c) return false;
  return std::all_of(c->begin(), c->end(), [x](double y) { return y == x; });
}

double tidy(double x) {
  if (x == 0 || !std::isfinite(x)) return x;
  const double scale = std::pow(10.0, 11 - static_cast<int>(std::floor(std::log10(std::fabs(x)))));
  const double r = std::round(x * scale) / scale;
  return std::isfinite(r) ? r : x;
}

namespace {

/// Folds a component-wise operation on two literals with broadcasting, or nullopt.
template <class F>
std::optional<Value> fold2(const Value& a, const Value& b, F f) {
  auto x = literalOf(a), y = literalOf(b);
  if (!x || !y) return std::nullopt;
  if (x->size() != y->size() && x->size() != 1 && y->size() != 1) return std::nullopt;
  const std::size_t n = std::max(x->size(), y->size());
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = f((*x)[x->size() == 1 ? 0 : i], (*y)[y->size() == 1 ? 0 : i]);
    if (!std::isfinite(v)) return std::nullopt;
    r[i] = tidy(v);
  }
  return literal(r);
}

template <class F>
std::optional<Value> fold1(const Value& a, F f) {
  auto x = literalOf(a);
  if (!x) return std::nullopt;
  std::vector<double> r;
  for (double v : *x) {
    const double y = f(v);
    if (!std::isfinite(y)) return std::nullopt;
    r.push_back(tidy(y));
  }
  return literal(r);
}

}  // namespace

Value literal(const std::vector<double>& c) {
  if (c.size() == 1) return c[0];
  Json a = Json::array();
  for (double x : c) a.push_back(x);
  return a;
}

Value literal3(double r, double g, double b) { return Json::array({r, g, b}); }

Value binaryNode(const std::string& kind, const Value& a, const Value& b) {
  return Json{{"kind", kind}, {"a", a}, {"b", b}};
}

Value unaryNode(const std::string& kind, const Value& x) { return Json{{"kind", kind}, {"x", x}}; }

Value mul(const Value& a, const Value& b) {
  if (isLiteral(a, 1) && !(literalOf(a)->size() > 1 && !literalOf(b))) return b;
  if (isLiteral(b, 1) && !(literalOf(b)->size() > 1 && !literalOf(a))) return a;
  if (auto f = fold2(a, b, [](double x, double y) { return x * y; })) return *f;
  return binaryNode("multiply", a, b);
}

Value add(const Value& a, const Value& b) {
  if (isLiteral(a, 0) && literalOf(a)->size() == 1) return b;
  if (isLiteral(b, 0) && literalOf(b)->size() == 1) return a;
  if (auto f = fold2(a, b, [](double x, double y) { return x + y; })) return *f;
  return binaryNode("add", a, b);
}

Value sub(const Value& a, const Value& b) {
  if (isLiteral(b, 0) && literalOf(b)->size() == 1) return a;
  if (auto f = fold2(a, b, [](double x, double y) { return x - y; })) return *f;
  return binaryNode("subtract", a, b);
}

Value divide(const Value& a, const Value& b) {
  if (isLiteral(b, 1) && literalOf(b)->size() == 1) return a;
  if (auto f = fold2(a, b, [](double x, double y) { return y == 0 ? 0.0 : x / y; })) return *f;
  return binaryNode("divide", a, b);
}

Value vmin(const Value& a, const Value& b) {
  if (auto f = fold2(a, b, [](double x, double y) { return std::min(x, y); })) return *f;
  return binaryNode("min", a, b);
}

Value vmax(const Value& a, const Value& b) {
  if (auto f = fold2(a, b, [](double x, double y) { return std::max(x, y); })) return *f;
  return binaryNode("max", a, b);
}

Value vlerp(const Value& a, const Value& b, const Value& t) {
  if (isLiteral(t, 0) && literalOf(t)->size() == 1) return a;
  if (isLiteral(t, 1) && literalOf(t)->size() == 1) return b;
  if (a == b) return a;
  if (auto lt = literalOf(t); lt && lt->size() == 1) {
    const double w = (*lt)[0];
    if (auto f = fold2(a, b, [w](double x, double y) { return x + (y - x) * w; })) return *f;
  }
  return Json{{"kind", "lerp"}, {"a", a}, {"b", b}, {"t", t}};
}

Value oneMinus(const Value& x) {
  if (auto f = fold1(x, [](double v) { return 1 - v; })) return *f;
  return unaryNode("one_minus", x);
}

Value saturate(const Value& x) {
  if (auto f = fold1(x, [](double v) { return std::clamp(v, 0.0, 1.0); })) return *f;
  return unaryNode("saturate", x);
}

Value vabs(const Value& x) {
  if (auto f = fold1(x, [](double v) { return std::fabs(v); })) return *f;
  return unaryNode("abs", x);
}

Value vsqrt(const Value& x) {
  if (auto f = fold1(x, [](double v) { return std::sqrt(std::max(v, 0.0)); })) return *f;
  return unaryNode("sqrt", x);
}

Value vpow(const Value& x, const Value& y) {
  if (isLiteral(y, 1) && literalOf(y)->size() == 1) return x;
  if (auto f = fold2(x, y, [](double b, double e) {
        if (e == 0) return 1.0;
        b = std::max(b, 0.0);
        return b == 0 ? 0.0 : std::pow(b, e);
      }))
    return *f;
  return Json{{"kind", "pow"}, {"x", x}, {"y", y}};
}

Value vnormalize(const Value& x) {
  if (auto c = literalOf(x)) {
    double n = 0;
    for (double v : *c) n += v * v;
    n = std::sqrt(n);
    if (c->size() > 1 && n > 0) {
      std::vector<double> r;
      for (double v : *c) r.push_back(tidy(v / n));
      return literal(r);
    }
  }
  return unaryNode("normalize", x);
}

Value vdot(const Value& a, const Value& b) {
  auto x = literalOf(a), y = literalOf(b);
  if (x && y && x->size() == y->size()) {
    double s = 0;
    for (std::size_t i = 0; i < x->size(); ++i) s += (*x)[i] * (*y)[i];
    return tidy(s);
  }
  return binaryNode("dot", a, b);
}

Value vclamp(const Value& x, const Value& lo, const Value& hi) {
  if (isLiteral(lo, 0) && isLiteral(hi, 1) && literalOf(lo)->size() == 1 && literalOf(hi)->size() == 1) return saturate(x);
  auto l = literalOf(lo), h = literalOf(hi);
  if (l && h && l->size() == 1 && h->size() == 1) {
    const double a = (*l)[0], b = (*h)[0];
    if (auto f = fold1(x, [a, b](double v) { return std::min(std::max(v, a), b); })) return *f;
  }
  return Json{{"kind", "clamp"}, {"x", x}, {"lo", lo}, {"hi", hi}};
}

Value vlength(const Value& x) {
  if (auto c = literalOf(x)) {
    double n = 0;
    for (double v : *c) n += v * v;
    return tidy(std::sqrt(n));
  }
  return unaryNode("length", x);
}

Value swizzle(const Value& x, const std::string& channels) {
  if (auto c = literalOf(x)) {
    std::vector<double> r;
    for (char ch : channels) {
      const std::size_t i = std::string("xyzw").find(ch) != std::string::npos ? std::string("xyzw").find(ch)
                                                                               : std::string("rgba").find(ch);
      if (i == std::string::npos || (c->size() > 1 && i >= c->size())) return Json{{"kind", "swizzle"}, {"x", x}, {"channels", channels}};
      r.push_back(c->size() == 1 ? (*c)[0] : (*c)[i]);
    }
    return literal(r);
  }
  return Json{{"kind", "swizzle"}, {"x", x}, {"channels", channels}};
}

Value max3(const Value& rgb) {
  if (auto c = literalOf(rgb)) return c->size() == 1 ? (*c)[0] : std::max({(*c)[0], (*c)[1], (*c)[2]});
  return vmax(vmax(swizzle(rgb, "r"), swizzle(rgb, "g")), swizzle(rgb, "b"));
}

Value combine(const std::vector<Value>& c) {
  std::vector<double> lit;
  for (const auto& v : c)
    if (v.is_number()) lit.push_back(v.get<double>());
  if (lit.size() == c.size()) return literal(lit);
  static const char* const kPins[] = {"x", "y", "z", "w"};
  Json n = {{"kind", "combine"}};
  for (std::size_t i = 0; i < c.size() && i < 4; ++i) n[kPins[i]] = c[i];
  return n;
}

Value geometry(const std::string& attribute) { return Json{{"kind", "geometry"}, {"attribute", attribute}}; }

Value textureSample(const Value& textureInput, const Value& uv) {
  Json n = {{"kind", "texture"}, {"texture", textureInput}};
  if (!uv.is_null()) n["uv"] = uv;
  return n;
}

Value outputOf(const Value& nodeRef, const std::string& name) { return nodeRef.get<std::string>() + "." + name; }

Value namedValue(NodeWriter& w, const std::string& id, const Value& v) { return v.is_object() ? w.node(id, v) : v; }

Value iorToF0Value(const Value& ior) {
  if (ior.is_number()) {
    const double n = ior.get<double>();
    const double r = (n - 1) / (n + 1);
    return tidy(r * r);
  }
  return Json{{"kind", "ior_to_f0"}, {"ior", ior}};
}

}  // namespace substratec::blocks
