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
#include "core/util/temporary_path.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

struct Holder {
    std::string host;
    long pid = 0;
    bool operator==(const Holder&) const = default;
    std::string text() const { return "process " + std::to_string(pid) + " on " + host; }
};

Holder me() { return {host_name(), long(getpid())}; }

std::optional<Holder> read_holder(const fs::path& marker) {
    std::ifstream in(marker);
    Holder h;
    if (in >> h.host >> h.pid) return h;
    return std::nullopt;  // gone, or created but not written yet
}

// Creates the marker naming this process if nobody holds it; false when it exists.
bool take_marker(const fs::path& marker) {
    const int fd = open(marker.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) {
        if (errno == EEXIST) return false;
        throw Error(marker.string(), std::string("cannot create the marker: ") + std::strerror(errno));
    }
    const Holder self = me();
    const std::string text = self.host + " " + std::to_string(self.pid) + "\n";
    const bool written = ::write(fd, text.data(), text.size()) == ssize_t(text.size());
    close(fd);
    if (!written) {
        fs::remove(marker);
        throw Error(marker.string(), "cannot write the marker");
    }
    return true;
}

// Removes the marker only while it names `holder`: one taken over meanwhile is another's.
// The marker is first renamed away, so a marker created after the look is never removed;
// one renamed away by mistake is put back unless a newer one exists.
void remove_marker_of(const fs::path& marker, const Holder& holder) {
    const fs::path aside = temporary_sibling(marker);
    std::error_code ec;
    fs::rename(marker, aside, ec);
    if (ec) return;  // gone already
    if (read_holder(aside) != holder) fs::create_hard_link(aside, marker, ec);
    fs::remove(aside, ec);
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

bool compute(const fs::path& target, const fs::path& marker, const std::function<void(const fs::path&)>& write,
             const ProduceOnceOptions& options) {
    const fs::path temporary = temporary_sibling(target);
    std::error_code ec;
    try {
        Heartbeat heartbeat(marker, options.heartbeat);
        write(temporary);
        if (!fs::exists(temporary)) throw Error(target.string(), "the computation wrote no file");
        fs::rename(temporary, target);
    } catch (...) {
        fs::remove(temporary, ec);
        remove_marker_of(marker, me());
        throw;
    }
    remove_marker_of(marker, me());
    return true;
}

// What a holder that died while writing left: its temporaries of the target.
void remove_leftovers(const fs::path& target, const Holder& dead) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(target.parent_path(), ec))
        if (is_temporary_of(entry.path(), target, dead.host, dead.pid)) fs::remove(entry.path(), ec);
}

}  // namespace

bool produce_file_once(const fs::path& target, const std::function<void(const fs::path&)>& write,
                       const ProduceOnceOptions& options) {
    using Clock = std::chrono::steady_clock;
    fs::path marker = target;
    marker += ".computing";
    const std::string host = host_name();
    fs::file_time_type seen{};  // the marker's time when last looked at
    bool looked = false;
    Clock::time_point unchanged_since = Clock::now();
    bool said_waiting = false;
    auto say = [&options](const std::string& text) {
        if (options.say) options.say(text);
    };
    for (;;) {
        if (fs::exists(target)) return false;
        if (take_marker(marker)) {
            if (fs::exists(target)) {  // finished between the look and the marker
                remove_marker_of(marker, me());
                return false;
            }
            return compute(target, marker, write, options);
        }
        std::error_code ec;
        const fs::file_time_type time = fs::last_write_time(marker, ec);
        if (ec == std::errc::no_such_file_or_directory) continue;  // the holder just finished or gave up
        if (ec) throw Error(marker.string(), "cannot read the marker: " + ec.message());
        if (!looked || seen != time) {
            seen = time;
            looked = true;
            unchanged_since = Clock::now();
        }
        const std::optional<Holder> holder = read_holder(marker);
        const bool holder_gone_here = holder && holder->host == host && kill(pid_t(holder->pid), 0) != 0 && errno == ESRCH;
        // Times are compared on this machine's clock only (the marker's time is just
        // watched for change), so clocks that differ between nodes do not matter.
        const bool not_refreshed = Clock::now() - unchanged_since > options.stale_after;
        if (holder && (holder_gone_here || not_refreshed)) {
            say(target.string() + ": its holder, " + holder->text() + ", is gone; computing it here");
            remove_marker_of(marker, *holder);
            remove_leftovers(target, *holder);
            looked = false;
            continue;
        }
        if (!said_waiting) {
            say(target.string() + " is being computed by " + (holder ? holder->text() : "another process") +
                "; waiting for it");
            said_waiting = true;
        }
        std::this_thread::sleep_for(options.poll);
    }
}

}  // namespace gilab
