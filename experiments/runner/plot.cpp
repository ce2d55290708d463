#include "experiments/runner/plot.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sstream>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "core/util/error.hpp"
#include "core/image/image_io.hpp"

extern char** environ;

namespace gilab {

namespace fs = std::filesystem;

namespace {

// Okabe-Ito colours: distinguishable with colour-vision deficiencies and in greyscale
// print. Yellow is left out, it vanishes on white.
constexpr const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000"};
// Filled circle, square, triangle, inverted triangle, diamond, then open ones.
constexpr int kPointTypes[] = {7, 5, 9, 11, 13, 6, 4};
constexpr int kPaletteSize = int(sizeof kPalette / sizeof kPalette[0]);

// Single-quoted gnuplot strings expand nothing (no backslash escapes, no backquote
// command substitution, no macros); the only special character is the quote itself,
// written twice. Control characters would end the script line, so they become spaces.
std::string quote(const std::string& text) {
    std::string out = "'";
    for (char c : text) {
        if (c == '\'') out += "''";
        else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) out += ' ';
        else out += c;
    }
    return out + "'";
}

// Shortest text that reads back as the same double: deterministic and exact.
std::string number(double v) {
    char buffer[32];
    auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, result.ptr);
}

bool plottable(double x, double y, const Plot& plot) {
    if (!std::isfinite(x) || !std::isfinite(y)) return false;
    // A log axis has no place for zero or negative values.
    if ((plot.log_x && x <= 0) || (plot.log_y && y <= 0)) return false;
    return true;
}

struct Fd {
    int fd = -1;
    Fd() = default;
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() { close(); }
    void close() {
        if (fd >= 0) ::close(fd);
        fd = -1;
    }
};

struct ProcessResult {
    int status = 0;  // as from waitpid
    std::string out, err;
};

// Runs `argv` with `input` on stdin and collects stdout and stderr. All three streams
// are served from one poll loop, so a child that writes much before reading all of its
// input cannot deadlock against us. stdin is a socket so a child that exits early gives
// EPIPE from send(MSG_NOSIGNAL) instead of a SIGPIPE that would kill this process.
ProcessResult run_process(const std::string& executable, const std::vector<std::string>& args, const std::string& input) {
    int sv[2], po[2], pe[2];
    Fd in_parent, in_child, out_parent, out_child, err_parent, err_child;
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0)
        throw Error(executable, std::string("cannot create socket: ") + std::strerror(errno));
    in_parent.fd = sv[0], in_child.fd = sv[1];
    if (::pipe2(po, O_CLOEXEC) != 0) throw Error(executable, std::string("cannot create pipe: ") + std::strerror(errno));
    out_parent.fd = po[0], out_child.fd = po[1];
    if (::pipe2(pe, O_CLOEXEC) != 0) throw Error(executable, std::string("cannot create pipe: ") + std::strerror(errno));
    err_parent.fd = pe[0], err_child.fd = pe[1];

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in_child.fd, 0);
    posix_spawn_file_actions_adddup2(&actions, out_child.fd, 1);
    posix_spawn_file_actions_adddup2(&actions, err_child.fd, 2);
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(executable.c_str()));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    int spawn_error = ::posix_spawn(&pid, executable.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawn_error != 0) throw Error(executable, std::string("cannot start: ") + std::strerror(spawn_error));
    in_child.close(), out_child.close(), err_child.close();
    ::fcntl(in_parent.fd, F_SETFL, ::fcntl(in_parent.fd, F_GETFL) | O_NONBLOCK);

    ProcessResult result;
    size_t written = 0;
    if (input.empty()) in_parent.close();
    char buffer[65536];
    while (in_parent.fd >= 0 || out_parent.fd >= 0 || err_parent.fd >= 0) {
        pollfd fds[3] = {{in_parent.fd, POLLOUT, 0}, {out_parent.fd, POLLIN, 0}, {err_parent.fd, POLLIN, 0}};
        if (::poll(fds, 3, -1) < 0) {
            if (errno == EINTR) continue;
            break;  // cannot happen with valid descriptors; waitpid below still reaps the child
        }
        if (in_parent.fd >= 0 && fds[0].revents) {
            ssize_t n = ::send(in_parent.fd, input.data() + written, input.size() - written, MSG_NOSIGNAL);
            if (n > 0) written += size_t(n);
            // On EPIPE the child stopped reading (it failed); its exit status says why.
            if ((n < 0 && errno != EAGAIN && errno != EINTR) || written == input.size()) in_parent.close();
        }
        Fd* readers[2] = {&out_parent, &err_parent};
        std::string* sinks[2] = {&result.out, &result.err};
        for (int i = 0; i < 2; ++i) {
            if (readers[i]->fd < 0 || !fds[i + 1].revents) continue;
            ssize_t n = ::read(readers[i]->fd, buffer, sizeof buffer);
            if (n > 0) sinks[i]->append(buffer, size_t(n));
            else if (n == 0 || (errno != EINTR && errno != EAGAIN)) readers[i]->close();
        }
    }
    while (::waitpid(pid, &result.status, 0) < 0)
        if (errno != EINTR) throw Error(executable, std::string("waitpid failed: ") + std::strerror(errno));
    return result;
}

std::string find_on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
    size_t begin = 0;
    while (begin <= dirs.size()) {
        size_t end = dirs.find(':', begin);
        if (end == std::string::npos) end = dirs.size();
        std::string dir = dirs.substr(begin, end - begin);
        fs::path candidate = fs::path(dir.empty() ? "." : dir) / program;
        struct stat st;
        if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
            return candidate.string();
        begin = end + 1;
    }
    return {};
}

std::string where(const Plot& plot) { return plot.title.empty() ? "plot" : "plot '" + plot.title + "'"; }

std::string trimmed(std::string s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
    return s;
}

}  // namespace

std::string gnuplot_script(const Plot& plot) {
    std::ostringstream script;
    script << "set encoding utf8\n"
           // noenhanced: labels are literal text, '_' and '^' are not sub/superscripts.
           << "set terminal svg size 720,480 fixed noenhanced font 'sans-serif,13' background rgb 'white'\n";
    if (!plot.title.empty()) script << "set title " << quote(plot.title) << "\n";
    if (!plot.x_label.empty()) script << "set xlabel " << quote(plot.x_label) << "\n";
    if (!plot.y_label.empty()) script << "set ylabel " << quote(plot.y_label) << "\n";
    if (plot.log_x) script << "set logscale x 10\n";
    if (plot.log_y) script << "set logscale y 10\n";
    script << "set grid back linetype 1 linecolor rgb '#e0e0e0' linewidth 1\n"
           << "set key outside below center horizontal reverse Left samplen 3 spacing 1.2\n"
           << "set border linecolor rgb '#404040'\n"
           // Axes hug the data with a small margin instead of growing to the next tick,
           // which on a log axis could waste a whole decade; end points stay unclipped.
           << "set autoscale fix\n"
           << "set offsets graph 0.03, graph 0.03, graph 0.05, graph 0.05\n";

    std::vector<std::string> clauses;
    for (size_t s = 0; s < plot.series.size(); ++s) {
        const PlotSeries& series = plot.series[s];
        if (series.x.size() != series.y.size())
            throw Error(where(plot), "series '" + series.label + "' has " + std::to_string(series.x.size()) +
                                         " x values but " + std::to_string(series.y.size()) + " y values");
        std::ostringstream data;
        size_t kept = 0;
        for (size_t i = 0; i < series.x.size(); ++i) {
            if (!plottable(series.x[i], series.y[i], plot)) continue;
            data << number(series.x[i]) << " " << number(series.y[i]) << "\n";
            ++kept;
        }
        if (kept == 0) continue;
        // Block names are indices, never labels, so no label text reaches a name.
        std::string block = "$series" + std::to_string(s);
        script << block << " << EOD\n" << data.str() << "EOD\n";
        int slot = (series.color >= 0 ? series.color : int(s)) % kPaletteSize;
        // A lone point drawn as a line would be invisible.
        bool points = series.points || kept == 1;
        std::ostringstream clause;
        clause << block << " using 1:2 with " << (points ? "linespoints" : "lines") << " linewidth 2 linecolor rgb '"
               << kPalette[slot] << "' dashtype " << (series.dashed ? "(8,5)" : "solid");
        if (points) clause << " pointtype " << kPointTypes[slot] << " pointsize 0.9";
        clause << " title " << quote(series.label);
        clauses.push_back(clause.str());
    }
    if (clauses.empty())
        throw Error(where(plot), "no plottable point (every series is empty, NaN/inf, or <= 0 on a log axis)");
    script << "plot ";
    for (size_t i = 0; i < clauses.size(); ++i) script << (i ? ", \\\n     " : "") << clauses[i];
    script << "\n";
    return script.str();
}

bool plotting_available() { return !find_on_path("gnuplot").empty(); }

std::string write_svg_plot(const Plot& plot, const fs::path& dir, const std::string& name) {
    // The name becomes a file name: no directories, no hidden files, nothing to quote.
    auto allowed = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'; };
    if (name.empty() || name.front() == '.' || !std::all_of(name.begin(), name.end(), allowed))
        throw Error("plot '" + name + "'", "plot name must be letters, digits, '_', '-' or '.' and not start with '.'");
    std::string file = name + ".svg";
    fs::path target = dir / file;
    std::string script = gnuplot_script(plot);
    std::string gnuplot = find_on_path("gnuplot");
    if (gnuplot.empty())
        throw Error(target.string(),
                    "gnuplot not found on PATH; install the Debian package gnuplot-nox (setup.sh does) to draw plots");
    // --default-settings: ignore ~/.gnuplot and the system gnuplotrc, so the figure
    // depends on the plot alone.
    ProcessResult run = run_process(gnuplot, {"--default-settings"}, script);
    std::string err = trimmed(run.err);
    if (!WIFEXITED(run.status) || WEXITSTATUS(run.status) != 0) {
        std::string how = WIFEXITED(run.status) ? "exit status " + std::to_string(WEXITSTATUS(run.status))
                                                : "signal " + std::to_string(WTERMSIG(run.status));
        throw Error(target.string(), "gnuplot failed (" + how + ")" + (err.empty() ? std::string() : ": " + err));
    }
    if (run.out.find("</svg>") == std::string::npos)
        throw Error(target.string(), "gnuplot wrote no complete SVG" + (err.empty() ? std::string() : ": " + err));
    fs::create_directories(dir);
    write_file_atomically(target, run.out);
    return file;
}

}  // namespace gilab
