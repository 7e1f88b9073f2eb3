// fmt's out-of-line code, compiled once for every target of the project.
//
// Debian ships fmt as headers plus a shared libfmt. The CLI links statically
// (a one-shot run is mostly dynamic loading otherwise: compiler/CMakeLists.txt),
// so the project used fmt header-only, and every translation unit then compiled
// fmt's formatting core again: about 3.5 s of a 4.5 s compile for a file that
// formats one float at -O2, in both CI builds. This file is what libfmt's own
// src/format.cc is: the inline-file definitions (FMT_FUNC is empty without
// FMT_HEADER_ONLY) and the explicit instantiations format.h declares extern.
// The `substratec_fmt` target (compiler/CMakeLists.txt) is this one file.
#include <fmt/format-inl.h>

FMT_BEGIN_NAMESPACE
namespace detail {

template FMT_API auto dragonbox::to_decimal(float x) noexcept -> dragonbox::decimal_fp<float>;
template FMT_API auto dragonbox::to_decimal(double x) noexcept -> dragonbox::decimal_fp<double>;

#ifndef FMT_STATIC_THOUSANDS_SEPARATOR
template FMT_API locale_ref::locale_ref(const std::locale& loc);
template FMT_API auto locale_ref::get<std::locale>() const -> std::locale;
#endif

template FMT_API auto thousands_sep_impl(locale_ref) -> thousands_sep_result<char>;
template FMT_API auto decimal_point_impl(locale_ref) -> char;
template FMT_API void buffer<char>::append(const char*, const char*);
template FMT_API void vformat_to(buffer<char>&, string_view, basic_format_args<FMT_BUFFER_CONTEXT(char)>,
                                 locale_ref);

template FMT_API auto thousands_sep_impl(locale_ref) -> thousands_sep_result<wchar_t>;
template FMT_API auto decimal_point_impl(locale_ref) -> wchar_t;
template FMT_API void buffer<wchar_t>::append(const wchar_t*, const wchar_t*);

}  // namespace detail
FMT_END_NAMESPACE
