// Text and contact sheets for `substratec preview --sweep`: a 5x7 bitmap font
// built in (A-Z, 0-9, space, .,:;-+=/()[]%#_<>'"?!*; lower case drawn as upper
// case, anything else as '?') and a grid of labelled tiles.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "preview/image.h"

namespace substratec::preview {

inline constexpr int kGlyphWidth = 5;    // pixels at scale 1
inline constexpr int kGlyphHeight = 7;
inline constexpr int kGlyphAdvance = 6;  // glyph + 1 column of spacing
inline constexpr int kLineAdvance = 9;   // glyph + 2 rows of spacing
inline constexpr int kSheetMargin = 8;   // around and between the cells of a sheet
inline constexpr std::array<float, 4> kSheetBackground{0.02f, 0.02f, 0.02f, 1.0f};

/// Whether `c` has its own glyph (lower case letters count: they map to upper case).
bool hasGlyph(char c);
/// The 7 rows of c's glyph, top first; bit 4 is the leftmost of the 5 columns.
std::array<uint8_t, kGlyphHeight> glyph(char c);
/// Width in pixels of the widest line of `text` at `scale` (no trailing spacing).
int textWidth(const std::string& text, int scale);

/// Draws `text` with its first glyph's top-left corner at (x, y): every set
/// font pixel becomes a scale x scale block of `colour` (replaced, not
/// blended); '\n' starts a new line kLineAdvance * scale lower. Clipped to
/// the image.
void drawText(Image& img, int x, int y, const std::string& text, std::array<float, 4> colour, int scale);

/// Tiles in a grid of `columns` (clamped to [1, tiles.size()]) on
/// kSheetBackground, each cell W x H (the largest tile; smaller tiles centred
/// horizontally, top-aligned) with its label in white under it. Label scale s =
/// clamp(W / 128, 1, 3), lowered until every label fits W; a label still too
/// wide is cut to the glyphs that fit. Layout: sheet width M + columns (W + M),
/// height M + rows (H + 7 s + 8 + M), M = kSheetMargin; tile i's top-left at
/// (M + col (W + M), M + row (H + 7 s + 8 + M)), its label 4 pixels below the
/// cell's tile area, left-aligned. Tiles are copied as they are, so pass
/// display-referred (tonemapped) tiles: the text is 1.0. Throws
/// std::invalid_argument for no tiles or more labels than tiles.
Image contactSheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels, int columns);

}  // namespace substratec::preview
