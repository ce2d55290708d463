// `gilab report`, the one page a researcher opens. On hand-made results: the contents
// grouped by paper, tables in their own scroll boxes, everything escaped, hidden runs
// and files outside a result's folder left out. On real results from the binary (two
// quick experiments and a comparison): every link the page makes resolves to a file on
// disk that decodes, the tags nest, and headless Chromium renders it (a screenshot that
// is not blank) with an empty console, no failed load, no broken image and no request
// beyond the disk. A control page proves the browser checks catch each failure.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "experiments/report/compare_report.hpp"
#include "experiments/report/html_report.hpp"
#include "experiments/runner/plot.hpp"
#include "tests/test_support.hpp"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

const char* const kChromium = "/usr/bin/chromium";

std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// ---- child processes -------------------------------------------------------------

struct ProcessResult {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

// Starts argv[0] without a shell in its own process group (so everything it spawns can
// be ended with it). extra_fds are dup2'ed to 3, 4, … in the child.
pid_t spawn(const std::vector<std::string>& argv, int output_fd, const std::vector<int>& extra_fds = {}) {
    const pid_t pid = fork();
    if (pid != 0) return pid;
    setpgid(0, 0);
    dup2(output_fd, 1);
    dup2(output_fd, 2);
    // Two steps so an fd already numbered 3 or 4 is not closed before it is copied.
    std::vector<int> copies;
    for (int fd : extra_fds) copies.push_back(fcntl(fd, F_DUPFD, 10));
    for (size_t i = 0; i < copies.size(); ++i) dup2(copies[i], int(3 + i));
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
}

// Ends what spawn started: the process group, then reaps the leader.
int end_process_group(pid_t pid) {
    kill(-pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    return status;
}

// Runs a program to its end, collecting its output; killed after `timeout`.
ProcessResult run_program(const std::vector<std::string>& argv, std::chrono::seconds timeout) {
    int out[2];
    if (pipe(out) != 0) return {-1, "pipe failed"};
    const pid_t pid = spawn(argv, out[1]);
    close(out[1]);
    ProcessResult r;
    const auto deadline = Clock::now() + timeout;
    int status = 0;
    bool exited = false;
    // Read until the program exits (its helpers may keep the pipe open longer).
    while (Clock::now() < deadline) {
        pollfd p{out[0], POLLIN, 0};
        if (poll(&p, 1, 100) > 0) {
            std::array<char, 4096> buffer{};
            const ssize_t n = ::read(out[0], buffer.data(), buffer.size());
            if (n > 0) r.output.append(buffer.data(), size_t(n));
            else if (exited) break;
        }
        if (!exited && waitpid(pid, &status, WNOHANG) == pid) exited = true;
        else if (exited && poll(&p, 1, 0) == 0) break;
    }
    close(out[0]);
    kill(-pid, SIGKILL);  // helpers left over, or the program itself on a timeout
    if (!exited) {
        waitpid(pid, &status, 0);
        r.output += "\n(killed after " + std::to_string(timeout.count()) + " s)";
        return r;
    }
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

ProcessResult run_gilab(const std::vector<std::string>& args) {
    std::vector<std::string> argv{gilab::test::gilab_program()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_program(argv, std::chrono::seconds(120));
}

// ---- the page as text ------------------------------------------------------------

std::string html_unescape(const std::string& s) {
    static const std::array<std::pair<const char*, char>, 5> entities{
        {{"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&#39;", '\''}, {"&amp;", '&'}}};
    std::string out;
    for (size_t i = 0; i < s.size();) {
        bool matched = false;
        for (const auto& [entity, c] : entities)
            if (s.compare(i, std::strlen(entity), entity) == 0) {
                out += c;
                i += std::strlen(entity);
                matched = true;
                break;
            }
        if (!matched) out += s[i++];
    }
    return out;
}

std::string percent_decode(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
            out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += s[i];
        }
    }
    return out;
}

// Every value of `attribute="…"` on the page, unescaped.
std::vector<std::string> attribute_values(const std::string& html, const std::string& attribute) {
    std::vector<std::string> values;
    const std::regex pattern("\\s" + attribute + "=\"([^\"]*)\"");
    for (auto it = std::sregex_iterator(html.begin(), html.end(), pattern); it != std::sregex_iterator(); ++it)
        values.push_back(html_unescape((*it)[1].str()));
    return values;
}

std::vector<std::string> references(const std::string& html) {
    std::vector<std::string> refs = attribute_values(html, "src");
    for (const auto& h : attribute_values(html, "href")) refs.push_back(h);
    return refs;
}

bool is_void_element(const std::string& tag) {
    static const std::set<std::string> kVoid{"area", "base", "br",   "col",   "embed", "hr",  "img",
                                             "input", "link", "meta", "source", "track", "wbr"};
    return kVoid.count(tag) > 0;
}

// What is wrong with the nesting of the page's tags: every element but the void ones
// must be closed, innermost first. The contents of <style> are skipped.
std::vector<std::string> nesting_problems(const std::string& html) {
    std::vector<std::string> problems, open;
    for (size_t i = html.find('<'); i != std::string::npos; i = html.find('<', i + 1)) {
        if (html.compare(i, 2, "<!") == 0) continue;  // the doctype
        const bool closing = html.compare(i, 2, "</") == 0;
        const size_t name_start = i + (closing ? 2 : 1);
        size_t name_end = name_start;
        while (name_end < html.size() && std::isalnum(static_cast<unsigned char>(html[name_end]))) ++name_end;
        const std::string tag = html.substr(name_start, name_end - name_start);
        if (tag.empty()) {
            problems.push_back("a bare '<' at byte " + std::to_string(i));
            continue;
        }
        if (closing) {
            if (open.empty() || open.back() != tag)
                problems.push_back("</" + tag + "> closes <" + (open.empty() ? "nothing" : open.back()) + ">");
            else open.pop_back();
        } else if (!is_void_element(tag)) {
            open.push_back(tag);
            if (tag == "style") i = html.find("</style>", i) - 1;
        }
    }
    for (const auto& tag : open) problems.push_back("<" + tag + "> is never closed");
    return problems;
}

// Checks one relative reference of the page: anchors exist, files exist and decode.
void expect_reference_resolves(const fs::path& root, const std::string& html, const std::string& ref) {
    SCOPED_TRACE(ref);
    ASSERT_FALSE(ref.empty());
    // Opening from disk without a network: no scheme, no host, no absolute path.
    ASSERT_EQ(ref.find("://"), std::string::npos);
    ASSERT_EQ(ref.find(':'), std::string::npos);
    ASSERT_NE(ref[0], '/');
    if (ref[0] == '#') {
        EXPECT_TRUE(contains(html, "id=\"" + ref.substr(1) + "\"")) << "no element with that id";
        return;
    }
    const fs::path file = root / percent_decode(ref);
    ASSERT_TRUE(fs::is_regular_file(file)) << file;
    const std::string extension = file.extension().string();
    if (extension == ".png") {
        int w = 0, h = 0, channels = 0;
        unsigned char* pixels = stbi_load(file.c_str(), &w, &h, &channels, 3);
        EXPECT_NE(pixels, nullptr) << "does not decode: " << stbi_failure_reason();
        EXPECT_GT(w * h, 0);
        stbi_image_free(pixels);
    } else if (extension == ".svg") {
        const std::string svg = read(file);
        EXPECT_TRUE(svg.rfind("<?xml", 0) == 0 || svg.rfind("<svg", 0) == 0) << svg.substr(0, 80);
        EXPECT_TRUE(contains(svg, "<svg") && contains(svg, "</svg>"));
    } else if (extension == ".html") {
        EXPECT_TRUE(contains(read(file), "</html>"));
    } else {
        ADD_FAILURE() << "the page links a file it cannot show: " << ref;
    }
}

// ---- Chromium --------------------------------------------------------------------

// Flags for a headless, offline Chromium: any host name fails to resolve, so a page
// reaching for the network shows up as a failed load rather than a silent download.
std::vector<std::string> chromium_command(const fs::path& profile) {
    return {kChromium,
            "--headless=new",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-extensions",
            "--no-first-run",
            "--no-default-browser-check",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--host-resolver-rules=MAP * ~NOTFOUND",
            "--user-data-dir=" + profile.string()};
}

// Lines of Chromium's own log (--enable-logging=stderr) that mean the page did not load
// cleanly. This Chromium logs every console message (any level) as INFO:CONSOLE, and the
// page runs no script, so any console line is a failure; it never logs failed resource
// loads there, which is why load_in_devtools() looks at the DevTools log as well.
std::vector<std::string> page_errors_in_log(const std::string& log) {
    std::vector<std::string> errors;
    std::istringstream lines(log);
    for (std::string line; std::getline(lines, line);)
        if (contains(line, ":CONSOLE") || contains(line, "Uncaught") || contains(line, "Failed to load resource") ||
            contains(line, "net::ERR_"))
            errors.push_back(line);
    return errors;
}

// Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe: it
// reads NUL-terminated JSON messages on fd 3 and writes its own on fd 4).
class DevTools {
public:
    explicit DevTools(const fs::path& profile) {
        int to_browser[2], from_browser[2];
        if (pipe(to_browser) != 0 || pipe(from_browser) != 0) return;
        log_fd_ = ::open("/dev/null", O_WRONLY);
        std::vector<std::string> argv = chromium_command(profile);
        argv.push_back("--remote-debugging-pipe");
        argv.push_back("--window-size=1280,2000");
        argv.push_back("about:blank");
        pid_ = spawn(argv, log_fd_, {to_browser[0], from_browser[1]});
        close(to_browser[0]);
        close(from_browser[1]);
        write_fd_ = to_browser[1];
        read_fd_ = from_browser[0];
    }
    ~DevTools() {
        if (pid_ > 0) {
            send("Browser.close", json::object(), "");
            // A moment to exit on its own, then whatever is left is ended.
            for (int i = 0; i < 50 && waitpid(pid_, nullptr, WNOHANG) == 0; ++i) usleep(100'000);
            end_process_group(pid_);
        }
        for (int fd : {write_fd_, read_fd_, log_fd_})
            if (fd >= 0) close(fd);
    }

    bool started() const { return pid_ > 0; }

    // Sends a command and waits for its answer; events that arrive meanwhile are kept.
    json call(const std::string& method, const json& params, const std::string& session) {
        const int id = send(method, params, session);
        while (std::optional<json> m = next_message()) {
            if (m->value("id", -1) == id) {
                if (m->contains("error")) throw gilab::Error("DevTools " + method, m->at("error").dump());
                return m->value("result", json::object());
            }
            events_.push_back(*m);
        }
        throw gilab::Error("DevTools " + method, "no answer from Chromium in time");
    }

    // Waits for an event of that name (or the deadline); returns every event seen.
    std::vector<json> events_until(const std::string& method) {
        while (std::none_of(events_.begin(), events_.end(), [&](const json& e) { return e.value("method", "") == method; })) {
            std::optional<json> m = next_message();
            if (!m) throw gilab::Error("DevTools", "no " + method + " from Chromium in time");
            events_.push_back(*m);
        }
        return events_;
    }

private:
    int send(const std::string& method, const json& params, const std::string& session) {
        json message{{"id", ++last_id_}, {"method", method}, {"params", params}};
        if (!session.empty()) message["sessionId"] = session;
        const std::string bytes = message.dump() + '\0';
        for (size_t done = 0; done < bytes.size();) {
            const ssize_t n = ::write(write_fd_, bytes.data() + done, bytes.size() - done);
            if (n <= 0) break;
            done += size_t(n);
        }
        return last_id_;
    }

    std::optional<json> next_message() {
        const auto deadline = Clock::now() + std::chrono::seconds(30);
        size_t end;
        while ((end = buffer_.find('\0')) == std::string::npos) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
            pollfd p{read_fd_, POLLIN, 0};
            if (left <= 0 || poll(&p, 1, int(left)) <= 0) return std::nullopt;
            std::array<char, 65536> chunk{};
            const ssize_t n = ::read(read_fd_, chunk.data(), chunk.size());
            if (n <= 0) return std::nullopt;
            buffer_.append(chunk.data(), size_t(n));
        }
        json message = json::parse(buffer_.substr(0, end));
        buffer_.erase(0, end + 1);
        return message;
    }

    pid_t pid_ = -1;
    int write_fd_ = -1, read_fd_ = -1, log_fd_ = -1;
    int last_id_ = 0;
    std::string buffer_;
    std::vector<json> events_;
};

struct BrowserLoad {
    std::vector<std::string> errors;         // console errors, failed loads, exceptions
    std::vector<std::string> broken_images;  // <img> that did not decode in the browser
    std::vector<std::string> network;        // requests for anything but a file on disk
    std::vector<std::string> probes;         // what each probe expression returned, as a string
};

// Loads the page in a fresh tab and reports what DevTools would show in red; then runs
// each probe (a JavaScript expression, awaited if it is a promise) as a reader's action
// would, and keeps its string result. Errors the probes cause count like the page's own.
BrowserLoad load_in_devtools(const fs::path& page, const fs::path& profile, const std::vector<std::string>& probes = {}) {
    DevTools browser(profile);
    if (!browser.started()) throw gilab::Error(kChromium, "could not start");
    const std::string target =
        browser.call("Target.createTarget", {{"url", "about:blank"}}, "")["targetId"].get<std::string>();
    const std::string session =
        browser.call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}}, "")["sessionId"].get<std::string>();
    for (const char* domain : {"Log.enable", "Runtime.enable", "Network.enable", "Page.enable"})
        browser.call(domain, json::object(), session);
    browser.call("Page.navigate", {{"url", "file://" + fs::absolute(page).string()}}, session);
    browser.events_until("Page.loadEventFired");
    // Images are loaded by now (the load event waits for them); ask which did not decode.
    const json broken = browser.call(
        "Runtime.evaluate",
        {{"expression", "JSON.stringify(Array.from(document.images).filter(i => !i.complete || i.naturalWidth === 0)"
                        ".map(i => i.getAttribute('src')))"},
         {"returnByValue", true}},
        session);
    BrowserLoad load;
    for (const auto& src : json::parse(broken["result"].value("value", std::string("[]"))))
        load.broken_images.push_back(src.get<std::string>());
    for (const std::string& probe : probes) {
        const json r = browser.call(
            "Runtime.evaluate", {{"expression", probe}, {"awaitPromise", true}, {"returnByValue", true}}, session);
        load.probes.push_back(r.contains("exceptionDetails") ? "exception: " + r["exceptionDetails"].dump()
                                                             : r["result"].value("value", std::string("(no string)")));
    }
    for (const json& e : browser.events_until("Page.loadEventFired")) {
        const std::string method = e.value("method", "");
        const json params = e.value("params", json::object());
        if (method == "Log.entryAdded" && params["entry"].value("level", "") == "error")
            load.errors.push_back(params["entry"].value("text", "") + " " + params["entry"].value("url", ""));
        else if (method == "Runtime.exceptionThrown")
            load.errors.push_back(params["exceptionDetails"].dump());
        else if (method == "Runtime.consoleAPICalled" &&
                 (params.value("type", "") == "error" || params.value("type", "") == "assert"))
            load.errors.push_back("console." + params.value("type", "") + ": " + params["args"].dump());
        else if (method == "Network.requestWillBeSent" && params["request"].value("url", "").rfind("file://", 0) != 0)
            load.network.push_back(params["request"].value("url", ""));
    }
    return load;
}

struct Screenshot {
    int width = 0, height = 0;
    size_t distinct_colours = 0;
    double non_white_share = 0;
};

std::optional<Screenshot> decode_screenshot(const fs::path& png) {
    int w = 0, h = 0, channels = 0;
    unsigned char* pixels = stbi_load(png.c_str(), &w, &h, &channels, 3);
    if (!pixels) return std::nullopt;
    std::set<uint32_t> colours;
    size_t non_white = 0;
    for (size_t i = 0; i < size_t(w) * size_t(h); ++i) {
        const unsigned char* p = pixels + 3 * i;
        colours.insert(uint32_t(p[0]) << 16 | uint32_t(p[1]) << 8 | p[2]);
        non_white += p[0] < 250 || p[1] < 250 || p[2] < 250;
    }
    stbi_image_free(pixels);
    return Screenshot{w, h, colours.size(), double(non_white) / double(size_t(w) * size_t(h))};
}

// Renders the page with Chromium's own --screenshot and returns its log.
ProcessResult screenshot(const fs::path& page, const fs::path& profile, const fs::path& png) {
    std::vector<std::string> argv = chromium_command(profile);
    for (const std::string& a : {std::string("--enable-logging=stderr"), std::string("--v=0"),
                                 "--screenshot=" + png.string(), std::string("--window-size=1280,2000"),
                                 "file://" + fs::absolute(page).string()})
        argv.push_back(a);
    return run_program(argv, std::chrono::seconds(60));
}

#define SKIP_WITHOUT_CHROMIUM()                                                                                     \
    if (!fs::exists(kChromium))                                                                                     \
    GTEST_SKIP() << kChromium << " not found: install the Debian package chromium "                                \
                    "(apt-get install --no-install-recommends chromium)"

// ---- hand-made results -----------------------------------------------------------

json experiment_doc(const std::string& name, const std::string& paper) {
    return {{"experiment", name},
            {"paper", paper},
            {"description", "what " + name + " measures"},
            {"quick", true},
            {"seed", 7},
            {"threads", 3},
            {"git_revision", "abc123"},
            {"machine", {{"cpu", "Test CPU"}}},
            {"notes", json::array({"a note"})},
            {"files", json::array()},
            {"tables", json::array({{{"title", name + " table"},
                                     {"columns", {"scene", "ms", "paper ms"}},
                                     {"rows", json::array({{{"scene", "cornell"}, {"ms", 1.5}, {"paper ms", 2}}})}}})}};
}

void write_json(const fs::path& file, const json& doc) { gilab::test::write_file(file.parent_path(), file.filename().string(), doc.dump()); }

TEST(Report, ContentsGroupByPaperAndSkipHiddenRuns) {
    const fs::path root = gilab::test::temp_dir("report_contents");
    write_json(root / "z-core" / "results.json", experiment_doc("z-core", "core"));
    write_json(root / "pm-x" / "results.json", experiment_doc("pm-x", "P1"));
    write_json(root / "vct-x" / "results.json", experiment_doc("vct-x", "P3"));
    write_json(root / "dag-x" / "results.json", experiment_doc("dag-x", "P2"));
    write_json(root / ".dag-y.partial" / "results.json", experiment_doc("dag-y", "P2"));
    EXPECT_EQ(gilab::write_html_report(root), 4);

    const std::string html = read(root / "report.html");
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    EXPECT_TRUE(nesting_problems(html).empty()) << ::testing::PrintToString(nesting_problems(html));
    EXPECT_FALSE(contains(html, "dag-y"));
    const size_t nav_end = html.find("</nav>");
    ASSERT_NE(nav_end, std::string::npos);
    const std::string nav = html.substr(0, nav_end);
    // The papers in order, each with its experiment, then the core measurements.
    size_t at = 0;
    for (const char* part : {"P1 ", "href=\"#experiment-pm-x\"", "P2 ", "href=\"#experiment-dag-x\"", "P3 ",
                             "href=\"#experiment-vct-x\"", "Core", "href=\"#experiment-z-core\""}) {
        const size_t found = nav.find(part, at);
        ASSERT_NE(found, std::string::npos) << part << " missing or out of order in:\n" << nav;
        at = found;
    }
    // Every contents entry leads to its section, which carries the run line and notes.
    for (const auto& ref : references(html)) expect_reference_resolves(root, html, ref);
    EXPECT_TRUE(contains(html, "revision abc123, seed 7, 3 threads, <b>quick run</b>"));
    EXPECT_TRUE(contains(html, "<li>a note</li>"));
    EXPECT_TRUE(contains(html, "<th class=\"paper\">paper ms</th>"));
}

TEST(Report, TablesScrollInTheirOwnBox) {
    const fs::path root = gilab::test::temp_dir("report_tables");
    write_json(root / "pm-x" / "results.json", experiment_doc("pm-x", "P1"));
    gilab::write_html_report(root);
    const std::string html = read(root / "report.html");
    const std::regex table_in_box("<div class=\"table-scroll\"><table>");
    EXPECT_EQ(std::distance(std::sregex_iterator(html.begin(), html.end(), table_in_box), std::sregex_iterator()), 1);
    EXPECT_TRUE(contains(html, "div.table-scroll{overflow-x:auto"));
    EXPECT_TRUE(std::regex_search(html, std::regex("</table></div>")));
}

TEST(Report, EscapesEverythingAndLinksOnlyFilesInsideTheResult) {
    const fs::path root = gilab::test::temp_dir("report_escaping");
    json doc = experiment_doc("hostile", "P1");
    doc["description"] = "<script>alert(1)</script> & \"quotes\"";
    doc["notes"] = {"<b>bold</b>"};
    doc["tables"][0]["title"] = "<i>title</i>";
    doc["tables"][0]["columns"] = {"<col>"};
    doc["tables"][0]["rows"] = json::array({{{"<col>", "<td>"}}});
    doc["files"] = {"plot \"a\" #1.svg", "../escape.png", "/etc/passwd.png", "missing.png", "table.md"};
    write_json(root / "hostile" / "results.json", doc);
    gilab::test::write_file(root / "hostile", "plot \"a\" #1.svg", "<svg xmlns=\"http://www.w3.org/2000/svg\"></svg>");
    gilab::test::write_file(root, "escape.png", "not linked");
    gilab::write_html_report(root);

    const std::string html = read(root / "report.html");
    for (const char* raw : {"<script>", "<b>bold", "<i>title", "<col>", "<td><td>", "\"quotes\""})
        EXPECT_FALSE(contains(html, raw)) << raw;
    EXPECT_TRUE(contains(html, "&lt;script&gt;alert(1)&lt;/script&gt; &amp; &quot;quotes&quot;"));
    EXPECT_TRUE(nesting_problems(html).empty()) << ::testing::PrintToString(nesting_problems(html));
    // The file name survives as a URL (percent-encoded) and as a caption (escaped).
    EXPECT_TRUE(contains(html, "src=\"hostile/plot%20%22a%22%20%231.svg\""));
    EXPECT_TRUE(contains(html, "<figcaption>plot &quot;a&quot; #1.svg</figcaption>"));
    EXPECT_FALSE(contains(html, "escape.png"));
    EXPECT_FALSE(contains(html, "passwd"));
    EXPECT_TRUE(contains(html, "Listed but missing: hostile/missing.png"));
    for (const auto& ref : references(html)) expect_reference_resolves(root, html, ref);
}

TEST(Report, ComparisonsAloneMakeAReportAndNothingIsAnError) {
    const fs::path root = gilab::test::temp_dir("report_compare_only");
    EXPECT_TRUE(contains(gilab::test::error_of([&] { gilab::write_html_report(root); }), "no results"));
    EXPECT_FALSE(fs::exists(root / "report.html"));

    const json comparison = {{"scene", "cornell"}, {"views", "mono"}, {"width", 4}, {"height", 4},
                             {"reference_spp", 16}, {"frames", 1},     {"threads", 2},
                             {"techniques", json::array({{{"technique", "path"}, {"frame_ms", 2.5}, {"relmse", 0.1},
                                                          {"ssim", 0.9}, {"flip", 0.05}},
                                                         {{"technique", "vct"}, {"frame_ms", 1618.7}, {"relmse", 0.116},
                                                          {"ssim", 0.7}, {"flip", 0.385}}})}};
    write_json(root / "compare" / "cornell" / "results.json", comparison);
    write_json(root / "compare" / ".cornell.partial" / "results.json", comparison);
    EXPECT_EQ(gilab::write_html_report(root), 0);
    const std::string html = read(root / "report.html");
    EXPECT_TRUE(contains(html, "href=\"#compare-cornell\""));
    EXPECT_TRUE(contains(html, "href=\"compare/cornell/index.html\""));
    EXPECT_FALSE(contains(html, "partial"));
    for (const char* column : {"technique", "frame (ms, median)", "relMSE", "SSIM", "FLIP (LDR, mean)", "HDR-FLIP (mean)"})
        EXPECT_TRUE(contains(html, std::string("<th>") + column + "</th>")) << column;
    EXPECT_TRUE(contains(html, "<td>2.5</td>"));
    // What `gilab report` prints at the end of the main job: a line per technique.
    const std::string summary = gilab::comparison_summary(root);
    EXPECT_TRUE(contains(summary, "\n  path  cornell 2.5 ms, relMSE 0.1, FLIP 0.05\n")) << summary;
    EXPECT_TRUE(contains(summary, "\n  vct   cornell 1619 ms, relMSE 0.116, FLIP 0.385\n")) << summary;
    EXPECT_FALSE(contains(summary, "partial")) << summary;
    EXPECT_EQ(gilab::comparison_summary(root / "nothing_here"), "");
    // The images were never written: named, not linked.
    for (const char* image : {"reference.png", "path.png", "path_flip.png"}) {
        EXPECT_TRUE(contains(html, std::string("Listed but missing: compare/cornell/") + image)) << image;
        EXPECT_FALSE(contains(html, std::string("src=\"compare/cornell/") + image)) << image;
    }
}

TEST(Report, AMalformedResultNamesItsFile) {
    const fs::path root = gilab::test::temp_dir("report_malformed");
    json doc = experiment_doc("bad", "P1");
    doc["tables"][0]["columns"] = {1, 2};
    write_json(root / "bad" / "results.json", doc);
    const std::string message = gilab::test::error_of([&] { gilab::write_html_report(root); });
    EXPECT_TRUE(contains(message, "bad/results.json")) << message;
    EXPECT_TRUE(contains(message, "malformed")) << message;
}

// ---- the browser -----------------------------------------------------------------

// A page with each kind of failure the browser checks look for: a missing image, an
// image that does not decode, a script error and a request for another host.
TEST(ReportBrowser, ChecksCatchAMissingImageABrokenImageAScriptErrorAndTheNetwork) {
    SKIP_WITHOUT_CHROMIUM();
    const fs::path dir = gilab::test::temp_dir("report_browser_control");
    gilab::test::write_file(dir, "broken.png", "not a png");
    const fs::path page = gilab::test::write_file(
        dir, "page.html",
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>t</title></head><body>"
        "<img src=\"missing.png\" alt=\"m\"><img src=\"broken.png\" alt=\"b\">"
        "<img src=\"http://example.invalid/x.png\" alt=\"n\"><script>undefinedFunction();</script></body></html>");

    const BrowserLoad load = load_in_devtools(page, dir / "profile");
    const std::string errors = ::testing::PrintToString(load.errors);
    EXPECT_TRUE(contains(errors, "Failed to load resource")) << errors;
    EXPECT_TRUE(contains(errors, "missing.png")) << errors;
    EXPECT_TRUE(contains(errors, "undefinedFunction")) << errors;
    EXPECT_EQ(load.broken_images.size(), 3u) << ::testing::PrintToString(load.broken_images);
    EXPECT_EQ(load.network, std::vector<std::string>{"http://example.invalid/x.png"});

    const ProcessResult shot = screenshot(page, dir / "profile2", dir / "shot.png");
    const std::vector<std::string> logged = page_errors_in_log(shot.output);
    EXPECT_TRUE(std::any_of(logged.begin(), logged.end(), [](const std::string& l) { return contains(l, "Uncaught"); }))
        << shot.output;
}

TEST(ReportBrowser, RealResultsOpenCleanlyInChromium) {
    if (!gilab::test::shared_asset("bunny/stanford-bunny.obj"))
        GTEST_SKIP() << "shared asset bunny/stanford-bunny.obj not found (vct-table1 needs it)";
    const fs::path root = gilab::test::temp_dir("report_browser");
    const std::string results = root.string();
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"experiment", "vct-table1", "dag-fig15", "--quick", "--results", results},
          std::vector<std::string>{"compare", "cornell", "-t", "path,photon", "-W", "24", "-H", "24", "--reference-spp",
                                   "16", "--frames", "1", "--results", results},
          std::vector<std::string>{"report", "--results", results}}) {
        const ProcessResult r = run_gilab(args);
        ASSERT_EQ(r.exit_code, 0) << ::testing::PrintToString(args) << "\n" << r.output;
    }
    const fs::path page = root / "report.html";
    const std::string html = read(page);

    // The page as text: nesting, contents, and every reference on disk and decodable.
    EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
    EXPECT_TRUE(nesting_problems(html).empty()) << ::testing::PrintToString(nesting_problems(html));
    for (const char* entry : {"href=\"#experiment-vct-table1\"", "href=\"#experiment-dag-fig15\"", "href=\"#compare-cornell\""})
        EXPECT_TRUE(contains(html, entry)) << entry;
    const std::vector<std::string> refs = references(html);
    for (const auto& ref : refs) expect_reference_resolves(root, html, ref);
    const auto linked = [&](const std::string& file) { return std::find(refs.begin(), refs.end(), file) != refs.end(); };
    for (const char* image : {"reference.png", "path.png", "path_flip.png", "photon.png", "photon_flip.png", "index.html"})
        EXPECT_TRUE(linked(std::string("compare/cornell/") + image)) << image;
    if (gilab::plotting_available()) {
        EXPECT_TRUE(std::any_of(refs.begin(), refs.end(), [](const std::string& r) {
            return r.rfind("dag-fig15/", 0) == 0 && r.size() > 4 && r.substr(r.size() - 4) == ".svg";
        })) << "dag-fig15's plots are not on the page";
    }

    // The page in a browser.
    SKIP_WITHOUT_CHROMIUM();
    const BrowserLoad load = load_in_devtools(page, root / "profile");
    EXPECT_TRUE(load.errors.empty()) << ::testing::PrintToString(load.errors);
    EXPECT_TRUE(load.broken_images.empty()) << ::testing::PrintToString(load.broken_images);
    EXPECT_TRUE(load.network.empty()) << ::testing::PrintToString(load.network);

    // The comparison page: the toggle flips a technique's image to the reference in place
    // and back, the reference decodes there, and a click enlarges an image three times.
    const std::string flip_probe = R"((async () => {
        const button = document.querySelector('button.flip');
        const img = document.getElementById(button.dataset.target);
        const seen = [img.getAttribute('src')];
        button.click();
        await img.decode();
        seen.push(img.getAttribute('src'), String(img.naturalWidth > 0), document.getElementById(button.dataset.target + '-caption').textContent);
        button.click();
        await img.decode();
        seen.push(img.getAttribute('src'));
        img.click();
        seen.push(String(img.getBoundingClientRect().width === 3 * img.naturalWidth));
        return JSON.stringify(seen);
    })())";
    const BrowserLoad compare_page = load_in_devtools(root / "compare" / "cornell" / "index.html", root / "profile3", {flip_probe});
    EXPECT_TRUE(compare_page.errors.empty()) << ::testing::PrintToString(compare_page.errors);
    EXPECT_TRUE(compare_page.broken_images.empty()) << ::testing::PrintToString(compare_page.broken_images);
    EXPECT_TRUE(compare_page.network.empty()) << ::testing::PrintToString(compare_page.network);
    ASSERT_EQ(compare_page.probes.size(), 1u);
    const std::string flipped_and_back =
        R"x(["path.png","reference.png","true","reference (path tracer)","path.png","true"])x";
    EXPECT_EQ(compare_page.probes[0], flipped_and_back);

    const ProcessResult shot = screenshot(page, root / "profile2", root / "shot.png");
    EXPECT_EQ(shot.exit_code, 0) << shot.output;
    EXPECT_TRUE(page_errors_in_log(shot.output).empty()) << ::testing::PrintToString(page_errors_in_log(shot.output));
    const std::optional<Screenshot> s = decode_screenshot(root / "shot.png");
    ASSERT_TRUE(s) << "no decodable screenshot; Chromium said:\n" << shot.output;
    EXPECT_EQ(s->width, 1280);
    EXPECT_GT(s->distinct_colours, 16u);
    EXPECT_GT(s->non_white_share, 0.01);
}

}  // namespace
