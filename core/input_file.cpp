#include "core/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include "core/error.hpp"
#include "core/memory_budget.hpp"

namespace gilab {

namespace fs = std::filesystem;

uint64_t input_file_size(const fs::path& path) {
    const std::string file = path.string();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw Error(file, "file not found");
    if (fs::is_directory(status)) throw Error(file, "is a directory, not a file");
    if (!fs::is_regular_file(status)) throw Error(file, "is not a regular file (a device, pipe or socket)");
    const uintmax_t size = fs::file_size(path, ec);
    if (ec) throw Error(file, "cannot read file size: " + ec.message());
    return uint64_t(size);
}

std::string read_input_file(const fs::path& path) {
    const std::string file = path.string();
    const uint64_t size = input_file_size(path);
    MemoryBudget::check(size, "reading the whole file", file);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(file, std::string("cannot open file: ") + std::strerror(errno));
    std::string bytes(size_t(size), '\0');
    in.read(bytes.data(), std::streamsize(size));
    bytes.resize(size_t(in.gcount()));  // the file may have shrunk since it was measured
    return bytes;
}

void check_text_encoding(const std::string& bytes, const std::string& file, const std::string& format) {
    auto starts = [&](const char* prefix, size_t n) { return bytes.size() >= n && std::memcmp(bytes.data(), prefix, n) == 0; };
    const bool bom16 = starts("\xFF\xFE", 2) || starts("\xFE\xFF", 2);
    const size_t nul = bytes.find('\0');
    if (!bom16 && nul == std::string::npos) return;
    // UTF-16 text of ASCII characters has a NUL in every other byte.
    size_t nuls = 0;
    const size_t probe = std::min<size_t>(bytes.size(), 4096);
    for (size_t i = 0; i < probe; ++i) nuls += bytes[i] == '\0';
    if (bom16 || nuls * 3 >= probe)
        throw Error(file, "UTF-16 text is not supported (" +
                              std::string(bom16 ? "UTF-16 byte-order mark" : "NUL bytes between the characters") +
                              "); save the " + format + " file as UTF-8 or ASCII");
    throw Error(file, "NUL byte at offset " + std::to_string(nul) + ": a binary file, not " + format + " text");
}

}  // namespace gilab
