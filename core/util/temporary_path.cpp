#include "core/util/temporary_path.hpp"

#include <unistd.h>

#include <atomic>

namespace gilab {

namespace fs = std::filesystem;

std::string host_name() {
    char name[256] = {};
    gethostname(name, sizeof name - 1);
    return name;
}

namespace {

// ".NAME.tmp.HOST.PID." — appended piecewise: GCC 12 warns falsely (-Wrestrict) on "." + std::string.
std::string prefix(const fs::path& target, const std::string& host, long pid) {
    std::string name(1, '.');
    name += target.filename().string();
    name += ".tmp.";
    name += host;
    name += '.';
    name += std::to_string(pid);
    name += '.';
    return name;
}

}  // namespace

fs::path temporary_sibling(const fs::path& target) {
    static std::atomic<unsigned long> counter{0};
    return target.parent_path() / (prefix(target, host_name(), long(getpid())) + std::to_string(counter++));
}

bool is_temporary_of(const fs::path& file, const fs::path& target, const std::string& host, long pid) {
    // Also a temporary of such a temporary (a writer that makes its own): ..NAME.tmp.H.P.N.tmp.…
    const std::string name = file.filename().string();
    return file.parent_path() == target.parent_path() && name.starts_with(".") &&
           name.find(prefix(target, host, pid).substr(1)) != std::string::npos;
}

}  // namespace gilab
