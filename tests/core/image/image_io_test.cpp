#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"
#include "core/image/image_io.hpp"
#include "tests/test_support.hpp"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace gilab {
namespace {

namespace fs = std::filesystem;

using test::error_of;

std::string read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The EXR header, parsed by hand so the test does not trust the library it checks:
// attribute name -> (type, raw value).
std::map<std::string, std::pair<std::string, std::string>> exr_attributes(const fs::path& path) {
    std::string bytes = read_bytes(path);
    std::map<std::string, std::pair<std::string, std::string>> attrs;
    EXPECT_GE(bytes.size(), 8u);
    EXPECT_EQ(bytes.substr(0, 4), std::string("\x76\x2f\x31\x01", 4));
    size_t pos = 8;
    while (pos < bytes.size() && bytes[pos] != '\0') {
        std::string name(bytes.c_str() + pos);
        pos += name.size() + 1;
        std::string type(bytes.c_str() + pos);
        pos += type.size() + 1;
        int32_t size;
        std::memcpy(&size, bytes.data() + pos, 4);
        pos += 4;
        attrs[name] = {type, bytes.substr(pos, size_t(size))};
        pos += size_t(size);
    }
    return attrs;
}

std::vector<std::string> exr_string_vector(const std::string& raw) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos + 4 <= raw.size()) {
        int32_t n;
        std::memcpy(&n, raw.data() + pos, 4);
        out.push_back(raw.substr(pos + 4, size_t(n)));
        pos += 4 + size_t(n);
    }
    return out;
}

// Channel name -> pixel type (2 = FLOAT).
std::map<std::string, int> exr_channels(const std::string& raw) {
    std::map<std::string, int> out;
    size_t pos = 0;
    while (pos < raw.size() && raw[pos] != '\0') {
        std::string name(raw.c_str() + pos);
        pos += name.size() + 1;
        int32_t type;
        std::memcpy(&type, raw.data() + pos, 4);
        out[name] = type;
        pos += 16;
    }
    return out;
}

Film test_film(int w, int h, float seed) {
    Film film(w, h);
    film.add_layer("direct", 3);
    film.add_layer("normal", 3);
    film.add_layer("depth", 1);
    film.add_layer("weights", 4);
    int k = 0;
    for (const char* name : {"color", "direct", "normal", "depth", "weights"}) {
        for (float& v : film.layer(name).data) {
            // Values that would not survive a half-float or 8-bit detour.
            ++k;
            v = seed * std::sin(0.37f * float(k)) * std::pow(10.0f, float(k % 11) - 5.0f);
        }
    }
    film.layer("depth").data[3] = std::numeric_limits<float>::infinity();
    film.layer("color").data[0] = std::numeric_limits<float>::denorm_min();
    film.layer("color").data[1] = -0.0f;
    film.metadata["technique"] = "path_tracer";
    film.metadata["spp"] = "64";
    film.metadata["note"] = "unicode \xc3\xa9 and, commas";
    return film;
}

void expect_same_layers(const Film& a, const Film& b) {
    ASSERT_EQ(a.width(), b.width());
    ASSERT_EQ(a.height(), b.height());
    ASSERT_EQ(a.layers().size(), b.layers().size());
    for (const auto& [name, layer] : a.layers()) {
        ASSERT_TRUE(b.has_layer(name)) << name;
        const Layer& other = b.layer(name);
        ASSERT_EQ(layer.channels, other.channels) << name;
        ASSERT_EQ(layer.data.size(), other.data.size()) << name;
        // Bit-exact, including -0, denormals and infinity.
        EXPECT_EQ(std::memcmp(layer.data.data(), other.data.data(), layer.data.size() * sizeof(float)), 0)
            << name;
    }
}

std::vector<fs::path> listing(const fs::path& dir) {
    std::vector<fs::path> out;
    for (const auto& entry : fs::directory_iterator(dir)) out.push_back(entry.path().filename());
    std::sort(out.begin(), out.end());
    return out;
}

TEST(Film, LayersAndPixelAccess) {
    Film film(4, 3);
    EXPECT_TRUE(film.has_layer("color"));
    EXPECT_EQ(film.layer("color").data.size(), 36u);
    Layer& depth = film.add_layer("depth", 1);
    EXPECT_EQ(&film.add_layer("depth", 1), &depth);  // idempotent
    EXPECT_THROW(film.add_layer("depth", 3), Error);
    EXPECT_THROW(film.add_layer("bad.name"), Error);
    EXPECT_THROW(film.add_layer("two", 2), Error);
    film.set("color", 3, 2, Vec3(1, 2, 3));
    film.set("depth", 1, 0, 7.5f);
    EXPECT_EQ(film.get("color", 3, 2), Vec3(1, 2, 3));
    EXPECT_EQ(film.layer("color").data[(2 * 4 + 3) * 3 + 1], 2.0f);  // row-major, interleaved
    EXPECT_EQ(film.get("depth", 1, 0), Vec3(7.5f));
    EXPECT_THROW(film.get("color", 4, 0), Error);
    EXPECT_THROW(film.set("color", 0, -1, Vec3(0)), Error);
    EXPECT_THROW(film.set("depth", 0, 0, Vec3(1)), Error);
    EXPECT_THROW(film.set("color", 0, 0, 1.0f), Error);
    std::string missing = error_of([&] { film.layer("albedo"); });
    EXPECT_NE(missing.find("'albedo'"), std::string::npos) << missing;
}

TEST(Film, CheckResolutionRejectsInsaneSizes) {
    EXPECT_NO_THROW(check_resolution(1920, 1080));
    EXPECT_NO_THROW(check_resolution(1, 1));
    for (auto [w, h] : {std::pair{0, 10}, {10, 0}, {-5, 10}, {10, -1}}) {
        std::string message = error_of([&] { check_resolution(w, h); });
        EXPECT_NE(message.find(std::to_string(w) + "x" + std::to_string(h)), std::string::npos) << message;
        EXPECT_NE(message.find("positive"), std::string::npos) << message;
    }
    std::string huge = error_of([] { check_resolution(1000000, 1000000); });
    EXPECT_NE(huge.find("1000000x1000000"), std::string::npos) << huge;
    EXPECT_NE(huge.find("96000000000000 bytes"), std::string::npos) << huge;  // 1e12 px * 8 * 12 B
    {
        // The budget decides: 100 × 100 × 8 layers × 12 B = 960 000 B.
        ScopedMemoryLimit limit(959999);
        std::string message = error_of([] { check_resolution(100, 100, 8); });
        EXPECT_NE(message.find("960000 bytes"), std::string::npos) << message;
        EXPECT_NE(message.find("--memory-limit"), std::string::npos) << message;
    }
    {
        ScopedMemoryLimit limit(960000);
        EXPECT_NO_THROW(check_resolution(100, 100, 8));
    }
    EXPECT_THROW(Film(0, 5), Error);
    EXPECT_THROW(Film(1000000, 1000000), Error);  // refused before allocating
    EXPECT_THROW(Film(std::numeric_limits<int>::max(), std::numeric_limits<int>::max()), Error);
}

TEST(ImageIo, ExrRoundTripIsBitExactForEveryLayerAndKeepsMetadata) {
    auto dir = test::temp_dir("image_io_exr");
    Film film = test_film(7, 5, 1.0f);
    auto path = dir / "frame.exr";
    write_exr(path, film);
    ASSERT_TRUE(fs::exists(path));
    EXPECT_EQ(listing(dir), std::vector<fs::path>{"frame.exr"});  // no temp file left

    auto attrs = exr_attributes(path);
    auto channels = exr_channels(attrs["channels"].second);
    for (const char* name : {"R", "G", "B", "direct.R", "direct.G", "direct.B", "normal.B",
                             "depth.Y", "weights.A"}) {
        ASSERT_TRUE(channels.count(name)) << name;
        EXPECT_EQ(channels[name], 2) << name << " must be FLOAT";
    }
    EXPECT_EQ(channels.size(), 3u + 3u + 3u + 1u + 4u);
    EXPECT_EQ(attrs["technique"].first, "string");
    EXPECT_EQ(attrs["technique"].second, "path_tracer");

    Film back = read_exr(path);
    expect_same_layers(film, back);
    for (const auto& [key, value] : film.metadata) EXPECT_EQ(back.metadata.at(key), value) << key;
    EXPECT_EQ(back.metadata.count("gitRevision"), 1u);
    EXPECT_THROW(read_exr(path, "left"), Error);  // not a multi-view file

    // Overwriting replaces the file as a whole.
    write_exr(path, test_film(3, 2, 2.0f));
    EXPECT_EQ(read_exr(path).width(), 3);
}

TEST(ImageIo, MetadataCannotShadowStandardAttributes) {
    auto dir = test::temp_dir("image_io_meta");
    Film film(2, 2);
    film.metadata["compression"] = "none";
    std::string message = error_of([&] { write_exr(dir / "x.exr", film); });
    EXPECT_NE(message.find("compression"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(ImageIo, StereoExrUsesTheMultiViewConvention) {
    auto dir = test::temp_dir("image_io_stereo");
    Film left = test_film(6, 4, 1.0f), right = test_film(6, 4, -3.0f);
    right.metadata["technique"] = "ignored";
    auto path = dir / "stereo.exr";
    write_exr_stereo(path, left, right);

    auto attrs = exr_attributes(path);
    ASSERT_TRUE(attrs.count("multiView"));
    EXPECT_EQ(attrs["multiView"].first, "stringvector");
    EXPECT_EQ(exr_string_vector(attrs["multiView"].second),
              (std::vector<std::string>{"left", "right"}));
    auto channels = exr_channels(attrs["channels"].second);
    for (const char* name : {"R", "G", "B", "right.R", "right.G", "right.B", "direct.left.R",
                             "direct.right.R", "depth.left.Y", "depth.right.Y", "weights.right.A"}) {
        EXPECT_TRUE(channels.count(name)) << name;
    }
    EXPECT_EQ(channels.size(), 2u * (3 + 3 + 3 + 1 + 4));

    Film l = read_exr(path, "left"), r = read_exr(path, "right"), d = read_exr(path);
    expect_same_layers(left, l);
    expect_same_layers(right, r);
    expect_same_layers(left, d);  // left is the default view
    EXPECT_EQ(r.metadata.at("technique"), "path_tracer");  // metadata from the left film
    std::string message = error_of([&] { read_exr(path, "centre"); });
    EXPECT_NE(message.find("left, right"), std::string::npos) << message;

    Film small(3, 4);
    EXPECT_THROW(write_exr_stereo(dir / "bad.exr", left, small), Error);
    EXPECT_FALSE(fs::exists(dir / "bad.exr"));
}

TEST(ImageIo, PngHasTheRightSizeAndSrgbValues) {
    auto dir = test::temp_dir("image_io_png");
    Film film(5, 2);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    film.set("color", 0, 0, Vec3(0.0f, 1.0f, 0.5f));
    film.set("color", 1, 0, Vec3(0.002f, 0.21586f, 4.0f));  // 0.21586 -> sRGB 128/255
    film.set("color", 2, 0, Vec3(-1.0f, nan, 0.0f));
    film.set("color", 3, 0, Vec3(0.25f, 0.125f, 0.0f));
    film.set("color", 4, 1, Vec3(1.0f, 0.0f, 0.0f));  // marks the bottom row
    auto path = dir / "preview.png";
    write_png(path, film);

    int w = 0, h = 0, comp = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &w, &h, &comp, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(w, 5);
    EXPECT_EQ(h, 2);
    EXPECT_EQ(comp, 3);
    auto px = [&](int x, int y, int c) { return int(pixels[(y * w + x) * 3 + c]); };
    EXPECT_EQ(px(0, 0, 0), 0);
    EXPECT_EQ(px(0, 0, 1), 255);
    EXPECT_EQ(px(0, 0, 2), 188);   // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    EXPECT_EQ(px(1, 0, 0), 7);     // linear segment: 12.92 * 0.002 * 255 = 6.6
    EXPECT_EQ(px(1, 0, 1), 128);
    EXPECT_EQ(px(1, 0, 2), 255);   // clamped
    EXPECT_EQ(px(2, 0, 0), 255);   // NaN anywhere in the pixel: magenta
    EXPECT_EQ(px(2, 0, 1), 0);
    EXPECT_EQ(px(2, 0, 2), 255);
    EXPECT_EQ(px(3, 0, 0), 137);   // 0.25 -> 0.5371
    EXPECT_EQ(px(4, 1, 0), 255);   // top row first
    EXPECT_EQ(px(4, 0, 0), 0);
    stbi_image_free(pixels);

    // One stop up doubles linear values: 0.25 -> 0.5 -> 188, 0.125 -> 0.25 -> 137.
    write_png(path, film, 1.0f);
    pixels = stbi_load(path.c_str(), &w, &h, &comp, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(px(3, 0, 0), 188);
    EXPECT_EQ(px(3, 0, 1), 137);
    stbi_image_free(pixels);

    // A 1-channel layer shows as grey.
    film.add_layer("depth", 1);
    film.set("depth", 2, 1, 0.5f);
    write_png(dir / "depth.png", film, 0.0f, "depth");
    pixels = stbi_load((dir / "depth.png").c_str(), &w, &h, &comp, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(px(2, 1, 0), 188);
    EXPECT_EQ(px(2, 1, 1), 188);
    EXPECT_EQ(px(2, 1, 2), 188);
    stbi_image_free(pixels);
    EXPECT_THROW(write_png(dir / "none.png", film, 0.0f, "albedo"), Error);
    EXPECT_FALSE(fs::exists(dir / "none.png"));
}

TEST(ImageIo, SideBySidePngPutsLeftThenRight) {
    auto dir = test::temp_dir("image_io_sbs");
    Film left(3, 2), right(2, 2);
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 3; ++x) left.set("color", x, y, Vec3(1, 0, 0));
        for (int x = 0; x < 2; ++x) right.set("color", x, y, Vec3(0, 0, 1));
    }
    auto path = dir / "sbs.png";
    write_png_side_by_side(path, left, right);
    int w = 0, h = 0, comp = 0;
    unsigned char* pixels = stbi_load(path.c_str(), &w, &h, &comp, 3);
    ASSERT_NE(pixels, nullptr);
    EXPECT_EQ(w, 5);
    EXPECT_EQ(h, 2);
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 5; ++x) {
            const unsigned char* p = pixels + (y * w + x) * 3;
            EXPECT_EQ(int(p[0]), x < 3 ? 255 : 0) << x << "," << y;
            EXPECT_EQ(int(p[2]), x < 3 ? 0 : 255) << x << "," << y;
        }
    }
    stbi_image_free(pixels);
    Film taller(2, 3);
    EXPECT_THROW(write_png_side_by_side(dir / "bad.png", left, taller), Error);
    EXPECT_FALSE(fs::exists(dir / "bad.png"));
}

TEST(ImageIo, FailedWritesThrowNamingThePathAndLeaveNoFile) {
    auto dir = test::temp_dir("image_io_fail");
    Film film = test_film(4, 4, 1.0f);
    std::ofstream(dir / "plain_file") << "x";
    fs::create_directories(dir / "occupied" / "inside");

    const fs::path targets[] = {
        dir / "no_such_dir" / "out",       // parent does not exist
        dir / "plain_file" / "out",        // parent is a file
        dir / "occupied",                  // target is a non-empty directory
    };
    for (const auto& base : targets) {
        for (const std::string ext : {".exr", ".png", ".txt"}) {
            fs::path target = base == dir / "occupied" ? base : fs::path(base.string() + ext);
            std::string message = error_of([&] {
                if (ext == ".exr") write_exr(target, film);
                if (ext == ".png") write_png(target, film);
                if (ext == ".txt") write_file_atomically(target, "contents");
            });
            EXPECT_NE(message.find(target.string()), std::string::npos) << message;
        }
    }
    // Nothing new anywhere: no output, no temp files.
    EXPECT_EQ(listing(dir), (std::vector<fs::path>{"occupied", "plain_file"}));
    EXPECT_EQ(listing(dir / "occupied"), std::vector<fs::path>{"inside"});
    EXPECT_FALSE(fs::exists(dir / "no_such_dir"));
    EXPECT_EQ(read_bytes(dir / "plain_file"), "x");
}

TEST(ImageIo, WriteFileAtomicallyReplacesContents) {
    auto dir = test::temp_dir("image_io_atomic");
    auto path = dir / "table.md";
    write_file_atomically(path, "first version\n");
    EXPECT_EQ(read_bytes(path), "first version\n");
    std::string binary("a\0b\xff", 4);
    write_file_atomically(path, binary);
    EXPECT_EQ(read_bytes(path), binary);
    write_file_atomically(path, "");
    EXPECT_EQ(read_bytes(path), "");
    EXPECT_EQ(listing(dir), std::vector<fs::path>{"table.md"});
}

TEST(ImageIo, ReadingBrokenFilesFailsWithThePath) {
    auto dir = test::temp_dir("image_io_read");
    std::string missing = error_of([&] { read_exr(dir / "absent.exr"); });
    EXPECT_NE(missing.find((dir / "absent.exr").string()), std::string::npos) << missing;
    write_file_atomically(dir / "garbage.exr", "this is not an EXR file");
    std::string garbage = error_of([&] { read_exr(dir / "garbage.exr"); });
    EXPECT_NE(garbage.find("garbage.exr"), std::string::npos) << garbage;
}

}  // namespace
}  // namespace gilab
