#include "core/util/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include "core/util/error.hpp"
#include "core/util/memory_budget.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

const char* file_type_name(fs::file_type type) {
    switch (type) {
        case fs::file_type::directory: return "a directory";
        case fs::file_type::character: return "a character device";
        case fs::file_type::block: return "a block device";
        case fs::file_type::fifo: return "a FIFO (named pipe)";
        case fs::file_type::socket: return "a socket";
        default: return "something other than a file";
    }
}

}  // namespace

std::string non_regular_file_problem(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);  // follows symbolic links
    if (ec || !fs::exists(status) || fs::is_regular_file(status)) return "";
    return std::string("is ") + file_type_name(status.type()) + ", not a regular file";
}

bool regular_file_exists(const fs::path& path) {
    const std::string problem = non_regular_file_problem(path);
    if (!problem.empty()) throw Error(path.string(), problem);
    std::error_code ec;
    return fs::is_regular_file(path, ec);
}

uint64_t input_file_size(const fs::path& path) {
    const std::string file = path.string();
    if (!regular_file_exists(path)) throw Error(file, "file not found");
    std::error_code ec;
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
