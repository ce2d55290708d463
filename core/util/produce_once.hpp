#pragma once
// A file that several processes, possibly on several machines sharing a filesystem, may
// all need (a path-traced reference, say): the first to ask computes it, the others wait
// for it instead of computing it again. The one computing holds a marker file
// (TARGET.computing, created exclusively) naming its host and process and refreshes the
// marker's modification time while it works; the file appears whole, by rename. A marker
// whose holder is gone (on this host: its process no longer exists; from another host: not
// refreshed for `stale_after`) is taken over, so a crashed or killed holder does not make
// the others wait for ever.
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>

namespace gilab {

struct ProduceOnceOptions {
    std::chrono::milliseconds heartbeat{10000};    // how often the holder refreshes its marker
    std::chrono::milliseconds stale_after{120000};  // a marker unchanged this long has no holder
    std::chrono::milliseconds poll{500};           // how often a waiter looks again
    std::function<void(const std::string&)> say;   // progress (waiting, taking over); may be empty
};

// Makes sure `target` exists. When it does not and nobody is computing it, calls
// write(temporary) — a new file beside the target with the target's extension — and renames
// the temporary into place; when another holds the marker, waits until the target appears
// (or the holder is found gone, then takes over). Returns true when this call wrote the
// target. An exception from `write` leaves neither the target, the temporary nor the
// marker behind, and is passed on.
bool produce_file_once(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path& temporary)>& write,
                       const ProduceOnceOptions& options = {});

}  // namespace gilab
