#include "experiments/report/html_report.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "core/image/image_io.hpp"
#include "experiments/runner/result_writers.hpp"

namespace gilab {

namespace fs = std::filesystem;

std::string escape_html(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

namespace {

using json = nlohmann::json;

// One results.json found under the results root, with where its files live
// (relative to report.html) and the anchor of its section.
struct ResultPage {
    std::string folder;  // relative to the results root: "NAME" or "compare/SCENE"
    json doc;
    std::string anchor;
};

// The page is self-contained: no external fonts, scripts or style sheets, so it opens
// from disk without a network.
constexpr const char* kStyle =
    "body{font-family:sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;color:#222}"
    "nav ul{margin-top:.2em}nav h3{margin-bottom:0}"
    "section.result{border-top:1px solid #ccc;margin-top:2em}"
    "p.run{color:#555;font-size:90%}"
    "div.table-scroll{overflow-x:auto;margin-bottom:1em}"
    "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right;white-space:nowrap}"
    "th.paper,td.paper{background:#eef}"
    "div.figures{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start;margin-bottom:1em}"
    "figure{margin:0;flex:0 1 480px;max-width:100%}figure img{width:100%;height:auto}"
    "div.figures.images figure{flex:0 1 16em}div.figures.images img{image-rendering:pixelated}"
    "figcaption{font-size:90%;color:#444}";

// A relative URL for a path under the results root: every byte but unreserved ones and
// '/' percent-encoded, so names with '#', '?', '%' or spaces still resolve to the file.
std::string relative_url(const std::string& path) {
    static constexpr char kHex[] = "0123456789ABCDEF";
    std::string out;
    for (unsigned char c : path) {
        if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
            out += char(c);
        } else {
            out += '%';
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    return out;
}

std::string text_of(const json& doc, const char* key, const std::string& fallback = "") {
    const auto it = doc.find(key);
    return it != doc.end() && it->is_string() ? it->get<std::string>() : fallback;
}

bool is_hidden(const fs::path& dir) { return dir.filename().string().rfind('.', 0) == 0; }

// A file a results.json lists may be shown only if it lies inside its own folder.
bool is_plain_relative(const std::string& file) {
    const fs::path p(file);
    if (file.empty() || p.is_absolute() || p.has_root_name()) return false;
    return std::none_of(p.begin(), p.end(), [](const fs::path& part) { return part == ".."; });
}

json read_results(const fs::path& path) {
    std::ifstream in(path);
    try {
        json doc = json::parse(in);
        if (!doc.is_object()) throw Error(path.string(), "malformed results file: not a JSON object");
        return doc;
    } catch (const json::exception& e) {
        throw Error(path.string(), std::string("malformed results file: ") + e.what());
    }
}

// Anchors are ids: no spaces, unique on the page.
std::string unique_anchor(const std::string& prefix, const std::string& name, std::set<std::string>& taken) {
    std::string base = prefix;
    for (unsigned char c : name) base += std::isalnum(c) || c == '-' || c == '_' ? char(c) : '_';
    std::string anchor = base;
    for (int n = 2; !taken.insert(anchor).second; ++n) anchor = base + "-" + std::to_string(n);
    return anchor;
}

// Every DIR/results.json directly under root/subfolder whose DIR is not hidden (hidden folders
// are runs in progress or interrupted), sorted by folder name.
std::vector<ResultPage> find_results(const fs::path& root, const std::string& subfolder, const std::string& anchor_prefix,
                                     std::set<std::string>& anchors) {
    std::vector<fs::path> dirs;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(root / subfolder, ec))
        if (!is_hidden(entry.path()) && fs::is_regular_file(entry.path() / "results.json", ec)) dirs.push_back(entry.path());
    std::sort(dirs.begin(), dirs.end());
    std::vector<ResultPage> pages;
    for (const auto& dir : dirs) {
        const std::string name = dir.filename().string();
        ResultPage page{subfolder.empty() ? name : subfolder + "/" + name, read_results(dir / "results.json"), ""};
        page.anchor = unique_anchor(anchor_prefix, name, anchors);
        pages.push_back(std::move(page));
    }
    return pages;
}

// The papers in the order the project lists them; any other "paper" value follows.
constexpr std::array<std::pair<const char*, const char*>, 4> kPapers{{
    {"P1", "P1 · Photon mapping for VR headsets"},
    {"P2", "P2 · Sparse voxel DAGs"},
    {"P3", "P3 · Cascaded voxel cone tracing"},
    {"core", "Core measurements"},
}};

std::string paper_of(const ResultPage& page) {
    const std::string paper = text_of(page.doc, "paper");
    return paper.empty() ? "other" : paper;
}

std::string paper_title(const std::string& paper) {
    for (const auto& [key, title] : kPapers)
        if (paper == key) return title;
    return paper;
}

std::vector<std::string> papers_in_order(const std::vector<ResultPage>& experiments) {
    std::vector<std::string> papers;
    for (const auto& [key, title] : kPapers)
        if (std::any_of(experiments.begin(), experiments.end(), [&](const ResultPage& e) { return paper_of(e) == key; }))
            papers.push_back(key);
    std::set<std::string> others;
    for (const auto& e : experiments)
        if (std::find(papers.begin(), papers.end(), paper_of(e)) == papers.end()) others.insert(paper_of(e));
    papers.insert(papers.end(), others.begin(), others.end());
    return papers;
}

std::string experiment_name(const ResultPage& page) {
    return text_of(page.doc, "experiment", page.folder);
}

void write_contents(std::ostringstream& html, const std::vector<std::string>& papers,
                    const std::vector<ResultPage>& experiments, const std::vector<ResultPage>& comparisons) {
    html << "<nav id=\"contents\">\n<h2>Contents</h2>\n";
    for (const auto& paper : papers) {
        html << "<h3>" << escape_html(paper_title(paper)) << "</h3>\n<ul>\n";
        for (const auto& e : experiments)
            if (paper_of(e) == paper) {
                const std::string description = text_of(e.doc, "description");
                html << "<li><a href=\"#" << e.anchor << "\">" << escape_html(experiment_name(e)) << "</a>"
                     << (description.empty() ? "" : " — " + escape_html(description)) << "</li>\n";
            }
        html << "</ul>\n";
    }
    if (!comparisons.empty()) {
        html << "<h3>Comparisons against the path-traced reference</h3>\n<ul>\n";
        for (const auto& c : comparisons)
            html << "<li><a href=\"#" << c.anchor << "\">" << escape_html(text_of(c.doc, "scene", c.folder)) << "</a> ("
                 << escape_html(text_of(c.doc, "views")) << ")</li>\n";
        html << "</ul>\n";
    }
    html << "</nav>\n";
}

bool is_paper_column(const std::string& column) { return column.rfind("paper", 0) == 0; }

// Wide tables scroll inside their own box rather than widening the page.
void write_table(std::ostringstream& html, const std::string& title, const std::vector<std::string>& columns,
                 const json& rows) {
    if (!title.empty()) html << "<h4>" << escape_html(title) << "</h4>\n";
    html << "<div class=\"table-scroll\"><table>\n<thead><tr>";
    for (const auto& c : columns) html << "<th" << (is_paper_column(c) ? " class=\"paper\"" : "") << ">" << escape_html(c) << "</th>";
    html << "</tr></thead>\n<tbody>\n";
    for (const auto& row : rows) {
        html << "<tr>";
        for (const auto& c : columns)
            html << "<td" << (is_paper_column(c) ? " class=\"paper\"" : "") << ">"
                 << escape_html(row.is_object() && row.contains(c) ? format_cell(row[c]) : "") << "</td>";
        html << "</tr>\n";
    }
    html << "</tbody></table></div>\n";
}

void write_notes(std::ostringstream& html, const json& doc) {
    std::vector<std::string> notes;
    for (const auto& n : doc.value("notes", json::array()))
        if (n.is_string()) notes.push_back(n.get<std::string>());
    if (notes.empty()) return;
    html << "<ul class=\"notes\">\n";
    for (const auto& n : notes) html << "<li>" << escape_html(n) << "</li>\n";
    html << "</ul>\n";
}

struct Figure {
    std::string file;  // relative to the results root
    std::string caption;
};

// A row of figures side by side. A listed file that is not on disk is named in a note
// instead of leaving a broken image on the page.
void write_figures(std::ostringstream& html, const fs::path& root, const std::vector<Figure>& figures,
                   const std::string& row_class) {
    std::vector<Figure> present;
    std::vector<std::string> missing;
    for (const auto& f : figures) {
        std::error_code ec;
        if (fs::is_regular_file(root / f.file, ec)) present.push_back(f);
        else missing.push_back(f.file);
    }
    if (!present.empty()) {
        html << "<div class=\"figures " << row_class << "\">\n";
        for (const auto& f : present)
            html << "<figure><img src=\"" << escape_html(relative_url(f.file)) << "\"><figcaption>" << escape_html(f.caption)
                 << "</figcaption></figure>\n";
        html << "</div>\n";
    }
    for (const auto& m : missing) html << "<p class=\"missing\">Listed but missing: " << escape_html(m) << "</p>\n";
}

std::vector<Figure> experiment_figures(const ResultPage& page, const std::string& extension) {
    std::vector<Figure> figures;
    for (const auto& f : page.doc.value("files", json::array())) {
        if (!f.is_string()) continue;
        const std::string file = f.get<std::string>();
        if (is_plain_relative(file) && fs::path(file).extension() == extension)
            figures.push_back({page.folder + "/" + file, file});
    }
    return figures;
}

void write_experiment(std::ostringstream& html, const fs::path& root, const ResultPage& page) {
    const json& doc = page.doc;
    html << "<section class=\"result experiment\" id=\"" << page.anchor << "\">\n<h3>" << escape_html(experiment_name(page))
         << "</h3>\n<p class=\"description\">" << escape_html(text_of(doc, "description")) << "</p>\n";
    const json machine = doc.value("machine", json::object());
    html << "<p class=\"run\">revision " << escape_html(text_of(doc, "git_revision", "?")) << ", seed "
         << escape_html(format_cell(doc.value("seed", json()))) << ", " << escape_html(format_cell(doc.value("threads", json())))
         << " threads" << (doc.value("quick", false) ? ", <b>quick run</b> (reduced sizes, not comparable to the paper)" : "")
         << ", " << escape_html(machine.is_object() ? text_of(machine, "cpu", "unknown CPU") : "unknown CPU");
    if (doc.contains("finished_utc")) html << ", finished " << escape_html(text_of(doc, "finished_utc"));
    html << "</p>\n";
    for (const auto& table : doc.value("tables", json::array())) {
        if (!table.is_object()) continue;
        write_table(html, text_of(table, "title"), table.value("columns", std::vector<std::string>()),
                    table.value("rows", json::array()));
    }
    write_notes(html, doc);
    write_figures(html, root, experiment_figures(page, ".svg"), "plots");
    write_figures(html, root, experiment_figures(page, ".png"), "images");
    html << "</section>\n";
}

// The comparison's own table, cut to the figures a reader compares techniques by.
void write_comparison_table(std::ostringstream& html, const json& techniques) {
    const bool equal_time = std::any_of(techniques.begin(), techniques.end(), [](const json& t) {
        return t.is_object() && !text_of(t, "quality_setting").empty();
    });
    std::vector<std::string> columns{"technique"};
    if (equal_time) columns.push_back("quality setting at equal time");
    for (const char* c : {"prepare (ms)", "frame (ms, median)", "relMSE", "SSIM", "FLIP (LDR, mean)", "HDR-FLIP (mean)"})
        columns.push_back(c);
    json rows = json::array();
    for (const auto& t : techniques) {
        if (!t.is_object()) continue;
        rows.push_back({{"technique", text_of(t, "technique")},
                        {"quality setting at equal time", text_of(t, "quality_setting")},
                        {"prepare (ms)", t.value("prepare_ms", json())},
                        {"frame (ms, median)", t.value("frame_ms", json())},
                        {"relMSE", t.value("relmse", json())},
                        {"SSIM", t.value("ssim", json())},
                        {"FLIP (LDR, mean)", t.value("flip", json())},
                        {"HDR-FLIP (mean)", t.value("hdr_flip", json())}});
    }
    write_table(html, "", columns, rows);
}

Figure reference_figure(const ResultPage& page) {
    return {page.folder + "/reference.png",
            "reference (path tracer, " + format_cell(page.doc.value("reference_spp", json())) + " spp)"};
}

// Each technique's image beside its FLIP map, named as `gilab compare` writes them.
std::vector<Figure> technique_figures(const ResultPage& page, const json& technique) {
    const std::string name = technique.is_object() ? text_of(technique, "technique") : "";
    if (!is_plain_relative(name)) return {};
    return {{page.folder + "/" + name + ".png", name},
            {page.folder + "/" + name + "_flip.png", name + " FLIP, mean " + format_cell(technique.value("flip", json()))}};
}

void write_comparison(std::ostringstream& html, const fs::path& root, const ResultPage& page) {
    const json& doc = page.doc;
    const json techniques = doc.value("techniques", json::array());
    html << "<section class=\"result comparison\" id=\"" << page.anchor << "\">\n<h3>" << escape_html(text_of(doc, "scene", page.folder))
         << "</h3>\n<p class=\"run\">" << escape_html(text_of(doc, "views")) << ", " << escape_html(format_cell(doc.value("width", json())))
         << "×" << escape_html(format_cell(doc.value("height", json()))) << ", reference "
         << escape_html(format_cell(doc.value("reference_spp", json()))) << " spp, median of "
         << escape_html(format_cell(doc.value("frames", json()))) << " frames at " << escape_html(format_cell(doc.value("threads", json())))
         << " threads, revision " << escape_html(text_of(doc, "git_revision", "?"));
    if (doc.contains("equal_time_seconds"))
        html << ", equal time of " << escape_html(text_of(doc, "equal_time_of", "frame")) << " at "
             << escape_html(format_cell(doc.value("equal_time_seconds", json()))) << " s";
    html << " — <a href=\""
         << escape_html(relative_url(page.folder + "/index.html")) << "\">full comparison page</a> (HDR-FLIP and 1 − SSIM maps, each image flipping to the reference)</p>\n";
    write_comparison_table(html, techniques);
    write_notes(html, doc);
    write_figures(html, root, {reference_figure(page)}, "images");
    for (const auto& t : techniques) write_figures(html, root, technique_figures(page, t), "images");
    html << "</section>\n";
}

// A field of the wrong type is bad input: the error names the results file.
template <class WriteSection>
void write_section(std::ostringstream& html, const fs::path& root, const ResultPage& page, WriteSection write) {
    try {
        write(html, root, page);
    } catch (const json::exception& e) {
        throw Error((root / page.folder / "results.json").string(), std::string("malformed results file: ") + e.what());
    }
}

}  // namespace

int write_html_report(const fs::path& results_root) {
    std::set<std::string> anchors{"contents", "comparisons"};
    const std::vector<ResultPage> experiments = find_results(results_root, "", "experiment-", anchors);
    const std::vector<ResultPage> comparisons = find_results(results_root, "compare", "compare-", anchors);
    if (experiments.empty() && comparisons.empty())
        throw Error(results_root.string(),
                    "no results/*/results.json found (run `gilab experiment` or `gilab compare` first)");
    const std::vector<std::string> papers = papers_in_order(experiments);

    std::ostringstream html;
    html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>gilab results</title>\n<style>"
         << kStyle << "</style>\n</head>\n<body>\n<h1>gilab results</h1>\n"
         << "<p>Shaded columns hold the papers' published figures (their hardware); all other figures were measured by "
            "the runs listed. Plots and images are the files beside each results.json.</p>\n";
    write_contents(html, papers, experiments, comparisons);
    html << "<main>\n";
    for (const auto& paper : papers) {
        html << "<h2>" << escape_html(paper_title(paper)) << "</h2>\n";
        for (const auto& e : experiments)
            if (paper_of(e) == paper) write_section(html, results_root, e, write_experiment);
    }
    if (!comparisons.empty()) {
        html << "<h2 id=\"comparisons\">Comparisons against the path-traced reference</h2>\n";
        for (const auto& c : comparisons) write_section(html, results_root, c, write_comparison);
    }
    html << "</main>\n</body>\n</html>\n";
    write_file_atomically(results_root / "report.html", html.str());
    return int(experiments.size());
}

}  // namespace gilab
