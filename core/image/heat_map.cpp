#include "core/image/heat_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include "core/util/error.hpp"
#include "core/image/image_io.hpp"

namespace gilab {

namespace {

// Nine stops of the ramp, evenly spaced.
constexpr double kRamp[9][3] = {
    {0.001, 0.000, 0.014}, {0.079, 0.054, 0.212}, {0.232, 0.060, 0.438}, {0.390, 0.100, 0.502}, {0.550, 0.161, 0.506},
    {0.716, 0.215, 0.475}, {0.869, 0.288, 0.409}, {0.968, 0.440, 0.360}, {0.987, 0.991, 0.750},
};

// 5×7 glyphs for the labels: digits, '.', '-', '+', 'e'.
struct Glyph {
    char c;
    const char* rows[7];
};
constexpr Glyph kGlyphs[] = {
    {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
    {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
    {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
    {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
    {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
    {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
    {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
    {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
    {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
    {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
    {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
    {'+', {"     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     "}},
    {'e', {"     ", "     ", " ### ", "#   #", "#####", "#    ", " ### "}},
};

const Glyph* glyph(char c) {
    for (const Glyph& g : kGlyphs)
        if (g.c == c) return &g;
    return nullptr;
}


class Canvas {
public:
    Canvas(int w, int h) : width_(w), height_(h), rgb_(size_t(w) * size_t(h) * 3, 255) {}
    void set(int x, int y, const std::array<uint8_t, 3>& c) {
        if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
        std::copy(c.begin(), c.end(), rgb_.begin() + long((size_t(y) * size_t(width_) + size_t(x)) * 3));
    }
    // Text at 2× scale in black, top-left at (x, y).
    void text(int x, int y, const std::string& s) {
        for (char c : s) {
            if (const Glyph* g = glyph(c))
                for (int row = 0; row < 7; ++row)
                    for (int col = 0; col < 5; ++col)
                        if (g->rows[row][col] == '#')
                            for (int k = 0; k < 4; ++k) set(x + 2 * col + k % 2, y + 2 * row + k / 2, {0, 0, 0});
            x += 12;
        }
    }
    static int text_width(const std::string& s) { return int(s.size()) * 12; }
    const std::vector<uint8_t>& rgb() const { return rgb_; }

private:
    int width_, height_;
    std::vector<uint8_t> rgb_;
};

std::string label(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", v);
    return buffer;
}

}  // namespace

std::array<uint8_t, 3> heat_colour(double t) {
    t = std::clamp(std::isnan(t) ? 0.0 : t, 0.0, 1.0) * 8.0;
    const int i = std::min(int(t), 7);
    const double f = t - i;
    std::array<uint8_t, 3> c{};
    for (int k = 0; k < 3; ++k)
        c[size_t(k)] = uint8_t(std::lround(255.0 * (kRamp[i][k] * (1.0 - f) + kRamp[i + 1][k] * f)));
    return c;
}

void write_heat_map_png(const std::filesystem::path& path, const ImagePlane& map, double low, double high) {
    if (map.width <= 0 || map.height <= 0 || map.values.size() != size_t(map.width) * size_t(map.height))
        throw Error(path.string(), "heat map: the map is empty or its size does not match its values");
    if (!std::isfinite(low) || !std::isfinite(high) || !(high > low))
        throw Error(path.string(), "heat map: the range [" + label(low) + ", " + label(high) + "] is not increasing and finite");
    const std::string lo = label(low), hi = label(high);
    const int width = std::max(map.width, Canvas::text_width(lo) + Canvas::text_width(hi) + 24);
    const int bar_top = map.height + 6, bar_height = 12, text_top = bar_top + bar_height + 4;
    Canvas canvas(width, text_top + 16);
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const float v = map.at(x, y);
            canvas.set(x, y, std::isnan(v) ? std::array<uint8_t, 3>{0, 255, 255} : heat_colour((v - low) / (high - low)));
        }
    for (int x = 0; x < width; ++x)
        for (int y = bar_top; y < bar_top + bar_height; ++y) canvas.set(x, y, heat_colour(double(x) / double(width - 1)));
    canvas.text(0, text_top, lo);
    canvas.text(width - Canvas::text_width(hi), text_top, hi);
    write_rgb_png(path, canvas.rgb(), width, text_top + 16);
}

}  // namespace gilab
