#pragma once
// One memory budget for everything whose size comes from input: counts read from files
// (vertices, faces, corners per face, list lengths, accessor counts, buffer lengths,
// frames) and settings that size allocations (resolutions, photon counts). A request is
// checked before anything is allocated, so a corrupt or hostile count ends in an Error
// naming the file, the field and the value, never in gigabytes of allocation or
// std::bad_alloc. The CLI sets the limit with --memory-limit.
//
// Each request is checked on its own against the limit; the budget keeps no running
// total. What a request grants ends up in long-lived objects (a scene's meshes, a film,
// a photon map) that have no point at which they would give it back, so a total could
// only grow, and a process that loads scene after scene would be refused for memory it
// has long freed. The limit therefore bounds any one size read from input, not the
// process's total memory.
#include <cstdint>
#include <string>

namespace gilab {

class MemoryBudget {
public:
    // The limit in bytes: what set_limit gave, else default_limit().
    static uint64_t limit();
    // 0 restores the default.
    static void set_limit(uint64_t bytes);
    // Half of the physical memory (or of the cgroup memory limit, if that is smaller).
    static uint64_t default_limit();

    // Throws Error "where: WHAT needs N, more than the memory limit of M ..." when
    // `bytes` exceeds the limit. `what` names the request, e.g. "element 'face' (12 faces)".
    static void check(uint64_t bytes, const std::string& what, const std::string& where);

    // A count read from a file. Each item occupies at least `min_file_bytes_each` bytes
    // of the file, so a count that needs more than `file_bytes_left` is a lie (corrupt
    // or truncated file); each item takes `memory_bytes_each` bytes once loaded, which
    // must fit the limit. `field` names the value, e.g. "face 3 corner count"; the
    // message quotes the count. Throws Error(where, ...).
    static void check_count(uint64_t count, uint64_t min_file_bytes_each, uint64_t file_bytes_left,
                            uint64_t memory_bytes_each, const std::string& field, const std::string& where);

    // "8G", "512M", "64k", "1.5G", "2GiB", "1000000" (bytes). K, M, G, T are powers of
    // 1024. Throws Error naming `option` and the text.
    static uint64_t parse_size(const std::string& text, const std::string& option);
    // "12 GiB", "1.5 MiB", "100 bytes".
    static std::string format(uint64_t bytes);

    // count × each, saturating at UINT64_MAX instead of wrapping around.
    static uint64_t times(uint64_t count, uint64_t each);
};

// Sets the limit for one scope and restores the previous one (tests, experiments).
class ScopedMemoryLimit {
public:
    explicit ScopedMemoryLimit(uint64_t bytes);
    ~ScopedMemoryLimit();
    ScopedMemoryLimit(const ScopedMemoryLimit&) = delete;
    ScopedMemoryLimit& operator=(const ScopedMemoryLimit&) = delete;

private:
    uint64_t previous_;
};

}  // namespace gilab
