#pragma once
// Names for files written beside their target and renamed into place when whole: hidden,
// and unique across the processes of every machine sharing the folder.
#include <filesystem>
#include <string>

namespace gilab {

// This machine's name (for temporary names and markers on shared folders).
std::string host_name();

// DIR/.NAME.tmp.HOST.PID.N for target DIR/NAME, N counting up within the process.
std::filesystem::path temporary_sibling(const std::filesystem::path& target);

// Whether `file` is a temporary_sibling of `target` (or of one of those) made by process
// `pid` on `host`: what a process that died while writing `target` leaves behind.
bool is_temporary_of(const std::filesystem::path& file, const std::filesystem::path& target, const std::string& host,
                     long pid);

}  // namespace gilab
