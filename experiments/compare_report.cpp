#include "experiments/compare_report.hpp"

#include <ctime>
#include <sstream>
#include "core/image_io.hpp"
#include "experiments/experiment.hpp"
#include "experiments/html_report.hpp"
#include "experiments/result_writers.hpp"

namespace gilab {

namespace {

ResultTable comparison_table(const CompareReport& r) {
    ResultTable t;
    t.title = "Techniques against a " + std::to_string(r.reference_spp) + "-spp path-traced reference, " + r.scene + ", " +
              std::to_string(r.width) + "×" + std::to_string(r.height) + " " + r.views;
    t.columns = {"technique"};
    if (r.equal_time_seconds) t.columns.push_back("quality setting at equal time");
    for (const char* c : {"prepare (ms)", "frame (ms, median)", "peak RSS (MiB, whole process)", "relMSE", "SSIM",
                          "FLIP (mean)"})
        t.columns.push_back(c);
    for (const auto& e : r.entries) {
        nlohmann::json row = {{"technique", e.technique},
                              {"prepare (ms)", e.prepare_ms},
                              {"frame (ms, median)", e.frame_ms},
                              {"peak RSS (MiB, whole process)", e.peak_rss_mib},
                              {"relMSE", e.relmse},
                              {"SSIM", e.ssim},
                              {"FLIP (mean)", e.flip}};
        if (r.equal_time_seconds) row["quality setting at equal time"] = e.knob;
        t.rows.push_back(row);
    }
    return t;
}

std::vector<std::string> notes(const CompareReport& r) {
    std::vector<std::string> n;
    std::ostringstream ppd;
    ppd << r.pixels_per_degree;
    n.push_back("relMSE over the colour layer (ε = 0.01); SSIM of the displayed luma and FLIP (LDR, " + ppd.str() +
                " pixels per degree) of the displayed image: linear colour clamped to [0, 1], as in the PNGs.");
    n.push_back("Frame time: the median of " + std::to_string(r.frames) + " renders at " + std::to_string(r.threads) +
                " threads after one prepare; the reference is the path tracer with jittered pixel samples, max depth 8.");
    n.push_back("Peak RSS: the process's peak resident memory while the technique ran, scene and reference included"
                " (the peak is reset before each technique where the kernel allows).");
    if (r.equal_time_seconds) {
        std::ostringstream s;
        s << *r.equal_time_seconds;
        n.push_back("Equal time: each technique's quality setting was scaled until a frame took about " + s.str() +
                    " s (within 10 %, at most five tries, assuming time grows in proportion to it); a technique"
                    " without such a setting ran as given.");
    }
    return n;
}

std::string html_page(const CompareReport& r, const ResultTable& table, const std::vector<std::string>& notes) {
    std::ostringstream h;
    h << "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>gilab compare: " << escape_html(r.scene)
      << "</title>\n<style>body{font-family:sans-serif;margin:1.5em}div.scroll{overflow-x:auto}"
         "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
         "figure{display:inline-block;margin:0 1em 1em 0;vertical-align:top}img{image-rendering:pixelated;"
         "max-width:100%}figcaption{font-size:90%}</style></head><body>\n";
    h << "<h1>" << escape_html(table.title) << "</h1>\n<div class=\"scroll\"><table>\n<tr>";
    for (const auto& c : table.columns) h << "<th>" << escape_html(c) << "</th>";
    h << "</tr>\n";
    for (const auto& row : table.rows) {
        h << "<tr>";
        for (const auto& c : table.columns) h << "<td>" << escape_html(row.contains(c) ? format_cell(row[c]) : "") << "</td>";
        h << "</tr>\n";
    }
    h << "</table></div>\n<ul>";
    for (const auto& n : notes) h << "<li>" << escape_html(n) << "</li>";
    h << "</ul>\n<h2>Images</h2>\n<figure><img src=\"reference.png\" alt=\"reference\"><figcaption>reference (path tracer, "
      << r.reference_spp << " spp)</figcaption></figure>\n";
    for (const auto& e : r.entries) {
        const std::string t = escape_html(e.technique);
        h << "<div><h3>" << t << "</h3>\n"
          << "<figure><img src=\"" << t << ".png\" alt=\"" << t << "\"><figcaption>" << t << "</figcaption></figure>\n"
          << "<figure><img src=\"" << t << "_flip.png\" alt=\"" << t << " FLIP\"><figcaption>FLIP, mean "
          << escape_html(format_cell(e.flip)) << "</figcaption></figure>\n"
          << "<figure><img src=\"" << t << "_ssim.png\" alt=\"" << t << " 1 − SSIM\"><figcaption>1 − SSIM, SSIM "
          << escape_html(format_cell(e.ssim)) << "</figcaption></figure></div>\n";
    }
    h << "</body></html>\n";
    return h.str();
}

}  // namespace

void write_compare_report(const std::filesystem::path& dir, const CompareReport& r) {
    const ResultTable table = comparison_table(r);
    const std::vector<std::string> n = notes(r);

    nlohmann::json doc;
    doc["scene"] = r.scene;
    doc["views"] = r.views;
    doc["width"] = r.width;
    doc["height"] = r.height;
    doc["reference_spp"] = r.reference_spp;
    doc["frames"] = r.frames;
    doc["threads"] = r.threads;
    doc["pixels_per_degree"] = r.pixels_per_degree;
    if (r.equal_time_seconds) doc["equal_time_seconds"] = *r.equal_time_seconds;
    doc["git_revision"] = git_revision();
    doc["machine"] = machine_description();
    doc["notes"] = n;
    nlohmann::json entries = nlohmann::json::array();
    for (const auto& e : r.entries)
        entries.push_back({{"technique", e.technique}, {"quality_setting", e.knob}, {"prepare_ms", e.prepare_ms},
                           {"frame_ms", e.frame_ms}, {"peak_rss_mib", e.peak_rss_mib},
                           {"peak_rss_reset", e.peak_rss_exact}, {"relmse", e.relmse}, {"ssim", e.ssim},
                           {"flip", e.flip}, {"settings", e.settings}, {"stats", e.stats},
                           {"files", {e.technique + ".exr", e.technique + ".png", e.technique + "_flip.png",
                                      e.technique + "_ssim.png"}}});
    doc["techniques"] = entries;
    doc["table"] = {{"title", table.title}, {"columns", table.columns}, {"rows", table.rows}};

    std::ostringstream md;
    md << "# gilab compare — " << r.scene << "\n\n" << to_markdown(table) << "\n";
    for (const auto& note : n) md << "- " << note << "\n";
    md << "\nImages: `reference.png` and, per technique, `TECHNIQUE.png` with its heat maps `TECHNIQUE_flip.png` and "
          "`TECHNIQUE_ssim.png` (1 − SSIM); `index.html` shows them side by side.\n";

    write_file_atomically(dir / "table.md", md.str());
    write_file_atomically(dir / "index.html", html_page(r, table, n));
    write_file_atomically(dir / "results.json", doc.dump(2) + "\n");
}

}  // namespace gilab
