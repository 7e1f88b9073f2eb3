// The built-in 5x7 font, text drawing and contact sheets (contact_sheet.h).
#include "preview/contact_sheet.h"

#include <algorithm>
#include <stdexcept>

namespace substratec::preview {

namespace {

struct GlyphArt {
  char c;
  const char* rows[kGlyphHeight];  // '#' set, '.' clear, 5 columns each
};

// clang-format off
constexpr GlyphArt kFont[] = {
  {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
  {'A', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
  {'B', {"####.", "#...#", "#...#", "####.", "#...#", "#...#", "####."}},
  {'C', {".###.", "#...#", "#....", "#....", "#....", "#...#", ".###."}},
  {'D', {"###..", "#..#.", "#...#", "#...#", "#...#", "#..#.", "###.."}},
  {'E', {"#####", "#....", "#....", "####.", "#....", "#....", "#####"}},
  {'F', {"#####", "#....", "#....", "####.", "#....", "#....", "#...."}},
  {'G', {".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".####"}},
  {'H', {"#...#", "#...#", "#...#", "#####", "#...#", "#...#", "#...#"}},
  {'I', {".###.", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
  {'J', {"..###", "...#.", "...#.", "...#.", "...#.", "#..#.", ".##.."}},
  {'K', {"#...#", "#..#.", "#.#..", "##...", "#.#..", "#..#.", "#...#"}},
  {'L', {"#....", "#....", "#....", "#....", "#....", "#....", "#####"}},
  {'M', {"#...#", "##.##", "#.#.#", "#.#.#", "#...#", "#...#", "#...#"}},
  {'N', {"#...#", "#...#", "##..#", "#.#.#", "#..##", "#...#", "#...#"}},
  {'O', {".###.", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
  {'P', {"####.", "#...#", "#...#", "####.", "#....", "#....", "#...."}},
  {'Q', {".###.", "#...#", "#...#", "#...#", "#.#.#", "#..#.", ".##.#"}},
  {'R', {"####.", "#...#", "#...#", "####.", "#.#..", "#..#.", "#...#"}},
  {'S', {".####", "#....", "#....", ".###.", "....#", "....#", "####."}},
  {'T', {"#####", "..#..", "..#..", "..#..", "..#..", "..#..", "..#.."}},
  {'U', {"#...#", "#...#", "#...#", "#...#", "#...#", "#...#", ".###."}},
  {'V', {"#...#", "#...#", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
  {'W', {"#...#", "#...#", "#...#", "#.#.#", "#.#.#", "#.#.#", ".#.#."}},
  {'X', {"#...#", "#...#", ".#.#.", "..#..", ".#.#.", "#...#", "#...#"}},
  {'Y', {"#...#", "#...#", ".#.#.", "..#..", "..#..", "..#..", "..#.."}},
  {'Z', {"#####", "....#", "...#.", "..#..", ".#...", "#....", "#####"}},
  {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
  {'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
  {'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
  {'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
  {'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
  {'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
  {'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
  {'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
  {'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
  {'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
  {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
  {',', {".....", ".....", ".....", ".....", ".##..", "..#..", ".#..."}},
  {':', {".....", ".##..", ".##..", ".....", ".##..", ".##..", "....."}},
  {';', {".....", ".##..", ".##..", ".....", ".##..", "..#..", ".#..."}},
  {'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
  {'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
  {'=', {".....", ".....", "#####", ".....", "#####", ".....", "....."}},
  {'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
  {'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
  {')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
  {'[', {".###.", ".#...", ".#...", ".#...", ".#...", ".#...", ".###."}},
  {']', {".###.", "...#.", "...#.", "...#.", "...#.", "...#.", ".###."}},
  {'%', {"##...", "##..#", "...#.", "..#..", ".#...", "#..##", "...##"}},
  {'#', {".#.#.", ".#.#.", "#####", ".#.#.", "#####", ".#.#.", ".#.#."}},
  {'_', {".....", ".....", ".....", ".....", ".....", ".....", "#####"}},
  {'<', {"...#.", "..#..", ".#...", "#....", ".#...", "..#..", "...#."}},
  {'>', {".#...", "..#..", "...#.", "....#", "...#.", "..#..", ".#..."}},
  {'\'', {"..#..", "..#..", ".#...", ".....", ".....", ".....", "....."}},
  {'"', {".#.#.", ".#.#.", ".#.#.", ".....", ".....", ".....", "....."}},
  {'?', {".###.", "#...#", "....#", "...#.", "..#..", ".....", "..#.."}},
  {'!', {"..#..", "..#..", "..#..", "..#..", "..#..", ".....", "..#.."}},
  {'*', {".....", "..#..", "#.#.#", ".###.", "#.#.#", "..#..", "....."}},
};
// clang-format on

/// The font as bit rows indexed by (unsigned char); present[c] marks glyphs.
struct FontTable {
  std::array<std::array<uint8_t, kGlyphHeight>, 256> rows{};
  std::array<bool, 256> present{};
  FontTable() {
    for (const GlyphArt& g : kFont) {
      auto idx = static_cast<unsigned char>(g.c);
      present[idx] = true;
      for (int r = 0; r < kGlyphHeight; ++r) {
        uint8_t bits = 0;
        for (int col = 0; col < kGlyphWidth; ++col)
          if (g.rows[r][col] == '#') bits |= static_cast<uint8_t>(1u << (kGlyphWidth - 1 - col));
        rows[idx][r] = bits;
      }
    }
  }
};

const FontTable& font() {
  static const FontTable table;
  return table;
}

/// c with lower case letters mapped to upper case.
unsigned char canonical(char c) {
  return (c >= 'a' && c <= 'z') ? static_cast<unsigned char>(c - 'a' + 'A') : static_cast<unsigned char>(c);
}

/// Fills the scale x scale block at (x, y), clipped to the image.
void block(Image& img, int x, int y, int scale, const std::array<float, 4>& colour) {
  for (int dy = 0; dy < scale; ++dy)
    for (int dx = 0; dx < scale; ++dx) {
      int px = x + dx, py = y + dy;
      if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
      std::copy(colour.begin(), colour.end(), img.pixel(px, py));
    }
}

/// The longest prefix of `label` whose width at `scale` is at most `width`.
std::string fitLabel(const std::string& label, int scale, int width) {
  size_t n = label.size();
  while (n > 0 && textWidth(label.substr(0, n), scale) > width) --n;
  return label.substr(0, n);
}

}  // namespace

bool hasGlyph(char c) { return font().present[canonical(c)]; }

std::array<uint8_t, kGlyphHeight> glyph(char c) {
  unsigned char idx = canonical(c);
  return font().rows[font().present[idx] ? idx : static_cast<unsigned char>('?')];
}

int textWidth(const std::string& text, int scale) {
  int widest = 0, count = 0;
  for (size_t i = 0; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == '\n') {
      widest = std::max(widest, count > 0 ? (count * kGlyphAdvance - (kGlyphAdvance - kGlyphWidth)) * scale : 0);
      count = 0;
    } else {
      ++count;
    }
  }
  return widest;
}

void drawText(Image& img, int x, int y, const std::string& text, std::array<float, 4> colour, int scale) {
  int penX = x, penY = y;
  for (char c : text) {
    if (c == '\n') {
      penX = x;
      penY += kLineAdvance * scale;
      continue;
    }
    std::array<uint8_t, kGlyphHeight> rows = glyph(c);
    for (int r = 0; r < kGlyphHeight; ++r)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (rows[r] & (1u << (kGlyphWidth - 1 - col))) block(img, penX + col * scale, penY + r * scale, scale, colour);
    penX += kGlyphAdvance * scale;
  }
}

Image contactSheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels, int columns) {
  if (tiles.empty()) throw std::invalid_argument("contactSheet: no tiles");
  if (labels.size() > tiles.size())
    throw std::invalid_argument("contactSheet: " + std::to_string(labels.size()) + " labels for " +
                                std::to_string(tiles.size()) + " tiles");
  const int count = static_cast<int>(tiles.size());
  const int cols = std::clamp(columns, 1, count);
  const int rows = (count + cols - 1) / cols;
  int W = 1, H = 1;
  for (const Image& t : tiles) {
    W = std::max(W, t.width);
    H = std::max(H, t.height);
  }
  int scale = std::clamp(W / 128, 1, 3);
  auto allFit = [&](int s) {
    return std::all_of(labels.begin(), labels.end(), [&](const std::string& l) { return textWidth(l, s) <= W; });
  };
  while (scale > 1 && !allFit(scale)) --scale;
  const int M = kSheetMargin, band = kGlyphHeight * scale + 8;
  Image sheet(M + cols * (W + M), M + rows * (H + band + M), kSheetBackground);
  for (int i = 0; i < count; ++i) {
    const Image& t = tiles[i];
    int cellX = M + (i % cols) * (W + M), cellY = M + (i / cols) * (H + band + M);
    int x0 = cellX + (W - t.width) / 2;
    for (int y = 0; y < t.height; ++y)
      std::copy(t.pixel(0, y), t.pixel(0, y) + static_cast<size_t>(t.width) * 4, sheet.pixel(x0, cellY + y));
    if (i < static_cast<int>(labels.size()))
      drawText(sheet, cellX, cellY + H + 4, fitLabel(labels[i], scale, W), {1.0f, 1.0f, 1.0f, 1.0f}, scale);
  }
  return sheet;
}

}  // namespace substratec::preview
