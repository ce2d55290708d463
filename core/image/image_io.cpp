#include "core/image/image_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMultiView.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <tuple>
#include <vector>
#include "core/util/build_info.hpp"
#include "core/util/error.hpp"
#include "core/util/temporary_path.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace gilab {

namespace fs = std::filesystem;

namespace {

// A temporary sibling of the target; removed unless commit() renamed it into place.
class TempFile {
public:
    explicit TempFile(const fs::path& target) : target_(target), path_(temporary_sibling(target)) {
        if (!target.has_filename()) throw Error(target.string(), "not a file path");
    }
    ~TempFile() {
        if (!committed_) {
            std::error_code ec;
            fs::remove(path_, ec);
        }
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    const fs::path& path() const { return path_; }
    void commit() {
        std::error_code ec;
        fs::rename(path_, target_, ec);
        if (ec) throw Error(target_.string(), "cannot move finished file into place: " + ec.message());
        committed_ = true;
    }

private:
    fs::path target_, path_;
    bool committed_ = false;
};

const char* const kRgba[4] = {"R", "G", "B", "A"};

std::vector<std::string> channel_suffixes(int channels) {
    if (channels == 1) return {"Y"};
    std::vector<std::string> names;
    for (int c = 0; c < channels && c < 4; ++c) names.push_back(kRgba[c]);
    return names;
}

// EXR channel name of one film channel before any view name is inserted.
std::string exr_channel_name(const std::string& layer, const std::string& suffix) {
    return layer == "color" ? suffix : layer + "." + suffix;
}

struct ChannelRef {
    std::string exr_name;
    const float* base;
    int stride;  // floats between neighbouring pixels
};

void add_film_channels(const Film& film, const std::string& path, const Imf::StringVector* views,
                       int view_index, Imf::Header& header, Imf::FrameBuffer& frame_buffer) {
    for (const auto& [name, layer] : film.layers()) {
        if (layer.data.size() != film.pixel_count() * size_t(layer.channels)) {
            throw Error(path, "film layer '" + name + "' has " + std::to_string(layer.data.size()) +
                                  " values, expected " +
                                  std::to_string(film.pixel_count() * size_t(layer.channels)));
        }
        if (name == "color" && layer.channels == 1) {
            throw Error(path, "the color layer must have 3 or 4 channels");
        }
        auto suffixes = channel_suffixes(layer.channels);
        if (int(suffixes.size()) != layer.channels) {
            throw Error(path, "film layer '" + name + "' has unsupported channel count " +
                                  std::to_string(layer.channels));
        }
        for (int c = 0; c < layer.channels; ++c) {
            std::string channel = exr_channel_name(name, suffixes[size_t(c)]);
            if (views) channel = Imf::insertViewName(channel, *views, view_index);
            header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
            size_t xs = sizeof(float) * size_t(layer.channels);
            // OpenEXR's Slice wants a non-const pointer even for writing.
            char* base = reinterpret_cast<char*>(const_cast<float*>(layer.data.data() + c));
            frame_buffer.insert(channel, Imf::Slice(Imf::FLOAT, base, xs, xs * size_t(film.width())));
        }
    }
}

void add_metadata(const Film& film, const std::string& path, Imf::Header& header) {
    auto metadata = film.metadata;
    metadata.emplace("gitRevision", build_git_revision());  // kept if the caller set one
    for (const auto& [key, value] : metadata) {
        if (key.empty()) throw Error(path, "metadata key is empty");
        if (header.find(key) != header.end()) {
            throw Error(path, "metadata key '" + key + "' clashes with a standard EXR attribute");
        }
        header.insert(key, Imf::StringAttribute(value));
    }
}

void write_exr_header(const fs::path& path, Imf::Header& header, Imf::FrameBuffer& frame_buffer,
                      int height) {
    TempFile temp(path);
    try {
        Imf::OutputFile file(temp.path().c_str(), header);
        file.setFrameBuffer(frame_buffer);
        file.writePixels(height);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path.string(), std::string("cannot write EXR: ") + e.what());
    }
    temp.commit();
}

uint8_t to_srgb8(float linear) {
    float v = std::clamp(linear, 0.0f, 1.0f);
    float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(std::clamp(s, 0.0f, 1.0f) * 255.0f));
}

// Writes the layer's tone-mapped RGB into rgb (row stride row_pixels), at column x0.
void tone_map_into(const Film& film, const std::string& layer_name, float exposure,
                   std::vector<uint8_t>& rgb, int row_pixels, int x0) {
    const Layer& layer = film.layer(layer_name);
    float scale = std::exp2(exposure);
    int ch = layer.channels;
    for (int y = 0; y < film.height(); ++y) {
        for (int x = 0; x < film.width(); ++x) {
            const float* p = layer.data.data() + (size_t(y) * size_t(film.width()) + size_t(x)) * size_t(ch);
            float c[3] = {p[0], ch >= 3 ? p[1] : p[0], ch >= 3 ? p[2] : p[0]};
            uint8_t* out = rgb.data() + (size_t(y) * size_t(row_pixels) + size_t(x0 + x)) * 3;
            if (std::isnan(c[0]) || std::isnan(c[1]) || std::isnan(c[2])) {
                out[0] = 255, out[1] = 0, out[2] = 255;  // magenta: NaN must be visible
                continue;
            }
            for (int k = 0; k < 3; ++k) out[k] = to_srgb8(c[k] * scale);
        }
    }
}

void append_bytes(void* context, void* data, int size) {
    auto* out = static_cast<std::string*>(context);
    out->append(static_cast<const char*>(data), size_t(size));
}

void check_exposure(const fs::path& path, float exposure) {
    if (!std::isfinite(exposure)) throw Error(path.string(), "exposure must be finite");
}

}  // namespace

void write_rgb_png(const fs::path& path, const std::vector<uint8_t>& rgb, int width, int height) {
    if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * size_t(height) * 3)
        throw Error(path.string(), "PNG pixels do not match the " + std::to_string(width) + "x" + std::to_string(height) + " size");
    std::string encoded;
    if (!stbi_write_png_to_func(append_bytes, &encoded, width, height, 3, rgb.data(), width * 3)) {
        throw Error(path.string(), "PNG encoding failed");
    }
    write_file_atomically(path, encoded);
}

void write_file_atomically(const fs::path& path, const std::string& contents) {
    TempFile temp(path);
    int fd = ::open(temp.path().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw Error(path.string(), std::string("cannot create file: ") + std::strerror(errno));
    size_t written = 0;
    while (written < contents.size()) {
        ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
        if (n < 0) {
            if (errno == EINTR) continue;
            int err = errno;
            ::close(fd);
            throw Error(path.string(), std::string("write failed: ") + std::strerror(err));
        }
        written += size_t(n);
    }
    // fsync before rename so a crash cannot leave a renamed but empty file.
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
        int err = errno;
        throw Error(path.string(), std::string("cannot flush file: ") + std::strerror(err));
    }
    temp.commit();
}

void write_exr(const fs::path& path, const Film& film) {
    check_resolution(film.width(), film.height(), 1);
    Imf::Header header(film.width(), film.height());
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer frame_buffer;
    add_film_channels(film, path.string(), nullptr, 0, header, frame_buffer);
    add_metadata(film, path.string(), header);
    write_exr_header(path, header, frame_buffer, film.height());
}

void write_exr_stereo(const fs::path& path, const Film& left, const Film& right) {
    check_resolution(left.width(), left.height(), 1);
    if (left.width() != right.width() || left.height() != right.height()) {
        throw Error(path.string(), "stereo views differ in size: left " +
                                       std::to_string(left.width()) + "x" +
                                       std::to_string(left.height()) + ", right " +
                                       std::to_string(right.width()) + "x" +
                                       std::to_string(right.height()));
    }
    Imf::Header header(left.width(), left.height());
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::StringVector views{"left", "right"};
    Imf::addMultiView(header, views);
    Imf::FrameBuffer frame_buffer;
    add_film_channels(left, path.string(), &views, 0, header, frame_buffer);
    add_film_channels(right, path.string(), &views, 1, header, frame_buffer);
    add_metadata(left, path.string(), header);
    write_exr_header(path, header, frame_buffer, left.height());
}

Film read_exr(const fs::path& path, const std::string& view) {
    try {
        if (!fs::exists(path)) throw Error(path.string(), "file does not exist");
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        const Imath::Box2i& dw = header.dataWindow();
        int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
        check_resolution(width, height, 1);

        // Map each wanted EXR channel to (layer, channel suffix).
        std::vector<std::pair<std::string, std::string>> wanted;  // exr name, logical name
        if (Imf::hasMultiView(header)) {
            const Imf::StringVector& views = Imf::multiView(header);
            std::string target = view.empty() ? Imf::defaultViewName(views) : view;
            if (std::find(views.begin(), views.end(), target) == views.end()) {
                std::string known;
                for (const auto& v : views) known += (known.empty() ? "" : ", ") + v;
                throw Error(path.string(), "no view '" + target + "' (views: " + known + ")");
            }
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
                std::string name = it.name();
                if (Imf::viewFromChannelName(name, views) != target) continue;
                wanted.emplace_back(name, Imf::removeViewName(name, target));
            }
        } else {
            if (!view.empty()) {
                throw Error(path.string(), "not a multi-view file; cannot select view '" + view + "'");
            }
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
                wanted.emplace_back(it.name(), it.name());
            }
        }

        std::map<std::string, std::set<std::string>> groups;  // layer -> suffixes
        std::vector<std::tuple<std::string, std::string, std::string>> channels;
        for (const auto& [exr_name, logical] : wanted) {
            size_t dot = logical.rfind('.');
            std::string layer = dot == std::string::npos ? "color" : logical.substr(0, dot);
            std::string suffix = dot == std::string::npos ? logical : logical.substr(dot + 1);
            groups[layer].insert(suffix);
            channels.emplace_back(exr_name, layer, suffix);
        }

        Film film(width, height);
        std::map<std::string, int> layer_channels;
        for (const auto& [layer, suffixes] : groups) {
            int count = 0;
            for (int n : {1, 3, 4}) {
                auto expected = channel_suffixes(n);
                if (std::set<std::string>(expected.begin(), expected.end()) == suffixes) count = n;
            }
            if (count == 0 || (layer == "color" && count == 1)) {
                std::string list;
                for (const auto& s : suffixes) list += (list.empty() ? "" : ",") + s;
                throw Error(path.string(), "layer '" + layer + "' has unsupported channels {" +
                                               list + "}; expected Y, R,G,B or R,G,B,A");
            }
            film.add_layer(layer, count);
            layer_channels[layer] = count;
        }

        Imf::FrameBuffer frame_buffer;
        for (const auto& [exr_name, layer, suffix] : channels) {
            int count = layer_channels[layer];
            auto suffixes = channel_suffixes(count);
            int c = int(std::find(suffixes.begin(), suffixes.end(), suffix) - suffixes.begin());
            Layer& l = film.layer(layer);
            size_t xs = sizeof(float) * size_t(count), ys = xs * size_t(width);
            // The slice base is shifted so that the data window origin lands on element 0.
            char* base = reinterpret_cast<char*>(l.data.data() + c) -
                         ptrdiff_t(dw.min.x) * ptrdiff_t(xs) - ptrdiff_t(dw.min.y) * ptrdiff_t(ys);
            frame_buffer.insert(exr_name, Imf::Slice(Imf::FLOAT, base, xs, ys));
        }
        file.setFrameBuffer(frame_buffer);
        file.readPixels(dw.min.y, dw.max.y);

        for (auto it = header.begin(); it != header.end(); ++it) {
            if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
                film.metadata[it.name()] = s->value();
            }
        }
        return film;
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path.string(), std::string("cannot read EXR: ") + e.what());
    }
}

void write_png(const fs::path& path, const Film& film, float exposure, const std::string& layer) {
    check_exposure(path, exposure);
    check_resolution(film.width(), film.height(), 1);
    if (!film.has_layer(layer)) throw Error(path.string(), "film has no layer '" + layer + "'");
    std::vector<uint8_t> rgb(film.pixel_count() * 3);
    tone_map_into(film, layer, exposure, rgb, film.width(), 0);
    write_rgb_png(path, rgb, film.width(), film.height());
}

void write_png_side_by_side(const fs::path& path, const Film& left, const Film& right,
                            float exposure) {
    check_exposure(path, exposure);
    check_resolution(left.width(), left.height(), 1);
    check_resolution(right.width(), right.height(), 1);
    if (left.height() != right.height()) {
        throw Error(path.string(), "side-by-side views differ in height: " +
                                       std::to_string(left.height()) + " vs " +
                                       std::to_string(right.height()));
    }
    int width = left.width() + right.width();
    std::vector<uint8_t> rgb(size_t(width) * size_t(left.height()) * 3);
    tone_map_into(left, "color", exposure, rgb, width, 0);
    tone_map_into(right, "color", exposure, rgb, width, left.width());
    write_rgb_png(path, rgb, width, left.height());
}

}  // namespace gilab
