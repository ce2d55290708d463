#include "core/texture/mip_map.hpp"
#include <array>
#include "core/image/display_planes.hpp"
#include "core/util/error.hpp"

namespace gilab {
namespace {

const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_decode(float(i) / 255.0f);
        return t;
    }();
    return table;
}

uint8_t encode(float linear, bool srgb) {
    const float v = std::clamp(linear, 0.0f, 1.0f);
    return uint8_t(std::lround((srgb ? srgb_encode(v) : v) * 255.0f));
}

// a + t (b − a): equal ends give exactly that value, so a constant texture reads back
// its texel value bit for bit wherever it is sampled.
Vec4 lerp(const Vec4& a, const Vec4& b, float t) { return a + t * (b - a); }

int wrap(int i, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::ClampToEdge: return std::clamp(i, 0, n - 1);
        case WrapMode::MirroredRepeat: {
            const int period = 2 * n;
            int m = i % period;
            if (m < 0) m += period;
            return m < n ? m : period - 1 - m;
        }
        case WrapMode::Repeat:
        default: {
            const int m = i % n;
            return m < 0 ? m + n : m;
        }
    }
}

// The source range [first, last] that destination index i of n_dst covers in n_src.
std::pair<int, int> source_span(int i, int n_dst, int n_src) {
    if (n_dst == n_src) return {i, i};
    const int first = 2 * i;
    const int last = (i == n_dst - 1) ? n_src - 1 : 2 * i + 1;  // an odd size folds its last texel in
    return {first, last};
}

Rgba8Image downsample(const Rgba8Image& src, const MipMap& decoder, bool srgb) {
    Rgba8Image dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.texels.resize(size_t(dst.width) * size_t(dst.height) * 4);
    for (int y = 0; y < dst.height; ++y) {
        const auto [y0, y1] = source_span(y, dst.height, src.height);
        for (int x = 0; x < dst.width; ++x) {
            const auto [x0, x1] = source_span(x, dst.width, src.width);
            Vec4 sum(0.0f);
            for (int sy = y0; sy <= y1; ++sy)
                for (int sx = x0; sx <= x1; ++sx) {
                    const uint8_t* t = &src.texels[(size_t(sy) * size_t(src.width) + size_t(sx)) * 4];
                    sum += Vec4(decoder.decode(t[0]), decoder.decode(t[1]), decoder.decode(t[2]), float(t[3]) / 255.0f);
                }
            const Vec4 mean = sum / float((y1 - y0 + 1) * (x1 - x0 + 1));
            uint8_t* out = &dst.texels[(size_t(y) * size_t(dst.width) + size_t(x)) * 4];
            for (int c = 0; c < 3; ++c) out[c] = encode(mean[c], srgb);
            out[3] = encode(mean[3], false);
        }
    }
    return dst;
}

}  // namespace

MipMap::MipMap(Rgba8Image base, ColorEncoding encoding, std::string name) : encoding_(encoding), name_(std::move(name)) {
    if (base.width <= 0 || base.height <= 0 || base.texels.size() != size_t(base.width) * size_t(base.height) * 4)
        throw Error(name_, "texture image has no texels or a texel count that does not match its size");
    levels_.push_back(std::move(base));
    while (levels_.back().width > 1 || levels_.back().height > 1)
        levels_.push_back(downsample(levels_.back(), *this, encoding_ == ColorEncoding::Srgb));
}

size_t MipMap::bytes() const {
    size_t n = 0;
    for (const Rgba8Image& level : levels_) n += level.texels.size();
    return n;
}

float MipMap::decode(uint8_t code) const {
    return encoding_ == ColorEncoding::Srgb ? srgb_table()[code] : float(code) / 255.0f;
}

Vec4 MipMap::texel(int level, int x, int y, WrapMode wrap_s, WrapMode wrap_t) const {
    const Rgba8Image& img = levels_[size_t(level)];
    x = wrap(x, img.width, wrap_s);
    y = wrap(y, img.height, wrap_t);
    const uint8_t* t = &img.texels[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
    return {decode(t[0]), decode(t[1]), decode(t[2]), float(t[3]) / 255.0f};
}

Vec4 MipMap::bilinear(int level, Vec2 st, WrapMode wrap_s, WrapMode wrap_t) const {
    const Rgba8Image& img = levels_[size_t(level)];
    // Texel centres sit at half-integer coordinates.
    const float x = st.x * float(img.width) - 0.5f, y = st.y * float(img.height) - 0.5f;
    if (!std::isfinite(x) || !std::isfinite(y)) return texel(level, 0, 0, wrap_s, wrap_t);
    const float fx = std::floor(x), fy = std::floor(y);
    // Coordinates far outside the image wrap the same way but must stay in int range.
    const float limit = 1e8f;
    const int x0 = int(std::clamp(fx, -limit, limit)), y0 = int(std::clamp(fy, -limit, limit));
    const float dx = x - fx, dy = y - fy;
    const Vec4 top = lerp(texel(level, x0, y0, wrap_s, wrap_t), texel(level, x0 + 1, y0, wrap_s, wrap_t), dx);
    const Vec4 bottom = lerp(texel(level, x0, y0 + 1, wrap_s, wrap_t), texel(level, x0 + 1, y0 + 1, wrap_s, wrap_t), dx);
    return lerp(top, bottom, dy);
}

Vec4 MipMap::trilinear(Vec2 st, float lod, WrapMode wrap_s, WrapMode wrap_t) const {
    const float top = float(levels() - 1);
    if (!(lod > 0.0f)) return bilinear(0, st, wrap_s, wrap_t);  // also NaN and −∞
    if (lod >= top) return bilinear(levels() - 1, st, wrap_s, wrap_t);
    const int below = int(lod);
    const float f = lod - float(below);
    const Vec4 a = bilinear(below, st, wrap_s, wrap_t);
    return f == 0.0f ? a : lerp(a, bilinear(below + 1, st, wrap_s, wrap_t), f);
}

float MipMap::level_for_footprint(float footprint) const {
    return std::log2(footprint * float(std::max(width(), height())));
}

}  // namespace gilab
