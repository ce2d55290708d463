#include "core/util/produce_once.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <fstream>
#include <mutex>
#include <optional>
#include <thread>
#include "core/util/error.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

std::string host_name() {
    char name[256] = {};
    gethostname(name, sizeof name - 1);
    return name;
}

struct Holder {
    std::string host;
    long pid = 0;
};

std::optional<Holder> read_holder(const fs::path& marker) {
    std::ifstream in(marker);
    Holder h;
    if (in >> h.host >> h.pid) return h;
    return std::nullopt;  // gone, or created but not written yet
}

// Creates the marker if nobody holds it; false when it exists.
bool take_marker(const fs::path& marker) {
    const int fd = open(marker.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        if (errno == EEXIST) return false;
        throw Error(marker.string(), std::string("cannot create the marker: ") + std::strerror(errno));
    }
    const std::string text = host_name() + " " + std::to_string(getpid()) + "\n";
    const bool written = ::write(fd, text.data(), text.size()) == ssize_t(text.size());
    close(fd);
    if (!written) {
        fs::remove(marker);
        throw Error(marker.string(), "cannot write the marker");
    }
    return true;
}

// Refreshes the marker's modification time every `period` until destroyed.
class Heartbeat {
public:
    Heartbeat(fs::path marker, std::chrono::milliseconds period)
        : thread_([this, marker = std::move(marker), period] {
              std::unique_lock lock(mutex_);
              while (!stop_cv_.wait_for(lock, period, [this] { return stopping_; })) {
                  std::error_code ec;
                  fs::last_write_time(marker, fs::file_time_type::clock::now(), ec);
              }
          }) {}
    ~Heartbeat() {
        {
            std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        stop_cv_.notify_all();
        thread_.join();
    }

private:
    std::mutex mutex_;
    std::condition_variable stop_cv_;
    bool stopping_ = false;
    std::thread thread_;
};

fs::path temporary_beside(const fs::path& target) {
    std::string name = ".";
    for (const std::string& part : {target.stem().string(), host_name(), std::to_string(getpid())}) name += part + ".";
    name.pop_back();
    return target.parent_path() / (name + target.extension().string());
}

bool compute(const fs::path& target, const fs::path& marker,
             const std::function<void(const fs::path&)>& write, const ProduceOnceOptions& options) {
    const fs::path temporary = temporary_beside(target);
    std::error_code ec;
    try {
        Heartbeat heartbeat(marker, options.heartbeat);
        write(temporary);
        if (!fs::exists(temporary)) throw Error(target.string(), "the computation wrote no file");
        fs::rename(temporary, target);
    } catch (...) {
        fs::remove(temporary, ec);
        fs::remove(marker, ec);
        throw;
    }
    fs::remove(marker, ec);
    return true;
}

}  // namespace

bool produce_file_once(const fs::path& target, const std::function<void(const fs::path&)>& write,
                       const ProduceOnceOptions& options) {
    using Clock = std::chrono::steady_clock;
    fs::path marker = target;
    marker += ".computing";
    const std::string host = host_name();
    std::optional<fs::file_time_type> seen;  // the marker's time when last looked at
    Clock::time_point unchanged_since = Clock::now();
    bool said_waiting = false;
    auto say = [&options](const std::string& text) {
        if (options.say) options.say(text);
    };
    for (;;) {
        if (fs::exists(target)) return false;
        if (take_marker(marker)) {
            if (fs::exists(target)) {  // finished between the look and the marker
                fs::remove(marker);
                return false;
            }
            return compute(target, marker, write, options);
        }
        std::error_code ec;
        const fs::file_time_type time = fs::last_write_time(marker, ec);
        if (ec) continue;  // the holder just finished or gave up: look again
        if (!seen || *seen != time) {
            seen = time;
            unchanged_since = Clock::now();
        }
        const std::optional<Holder> holder = read_holder(marker);
        const bool holder_gone_here = holder && holder->host == host && kill(pid_t(holder->pid), 0) != 0 && errno == ESRCH;
        // Times are compared on this machine's clock only (the marker's time is just
        // watched for change), so clocks that differ between nodes do not matter.
        const bool not_refreshed = Clock::now() - unchanged_since > options.stale_after;
        if (holder_gone_here || not_refreshed) {
            say(target.string() + ": its holder " + (holder ? holder->host + " " + std::to_string(holder->pid) : "?") +
                " is gone; computing it here");
            // Two waiters may both find the same dead holder; both then race for a new
            // marker and one wins. Rarely both compute: the rename makes that harmless.
            fs::remove(marker, ec);
            seen.reset();
            continue;
        }
        if (!said_waiting) {
            say(target.string() + " is being computed by " +
                (holder ? "process " + std::to_string(holder->pid) + " on " + holder->host : "another process") +
                "; waiting for it");
            said_waiting = true;
        }
        std::this_thread::sleep_for(options.poll);
    }
}

}  // namespace gilab
