#include "experiments/report/compare_report.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include "core/image/image_io.hpp"
#include "experiments/runner/experiment.hpp"
#include "experiments/report/html_report.hpp"
#include "experiments/runner/result_writers.hpp"

namespace gilab {

namespace {

ResultTable comparison_table(const CompareReport& r) {
    ResultTable t;
    t.title = "Techniques against a " + std::to_string(r.reference_spp) + "-spp path-traced reference, " + r.scene + ", " +
              std::to_string(r.width) + "×" + std::to_string(r.height) + " " + r.views;
    t.columns = {"technique"};
    if (r.equal_time_seconds) t.columns.push_back("quality setting at equal time");
    for (const char* c : {"prepare (ms)", "frame (ms, median)", "prepare + frame (ms)", "peak RSS (MiB, whole process)",
                          "relMSE", "SSIM", "FLIP (LDR, mean)", "HDR-FLIP (mean)"})
        t.columns.push_back(c);
    for (const auto& e : r.entries) {
        nlohmann::json row = {{"technique", e.technique},
                              {"prepare (ms)", e.prepare_ms},
                              {"frame (ms, median)", e.frame_ms},
                              {"prepare + frame (ms)", e.prepare_ms + e.frame_ms},
                              {"peak RSS (MiB, whole process)", e.peak_rss_mib},
                              {"relMSE", e.relmse},
                              {"SSIM", e.ssim},
                              {"FLIP (LDR, mean)", e.flip},
                              {"HDR-FLIP (mean)", e.hdr_flip}};
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
    n.push_back("HDR-FLIP (Andersson et al. 2021) of the linear colour itself: LDR-FLIP after the ACES tone curve at"
                " each of an exposure range taken from the reference (from its brightest pixel to its median), the"
                " largest error per pixel; it sees errors above 1 that the displayed image clamps away.");
    n.push_back("Frame time: the median of " + std::to_string(r.frames) + " renders at " + std::to_string(r.threads) +
                " threads after one prepare; the reference is the path tracer with jittered pixel samples, max depth 8.");
    n.push_back("Peak RSS: the process's peak resident memory while the technique ran, scene and reference included"
                " (the peak is reset before each technique where the kernel allows).");
    if (r.equal_time_seconds) {
        std::ostringstream s;
        s << *r.equal_time_seconds;
        const bool total = r.equal_time_of != "frame";
        n.push_back("Equal time of " + r.equal_time_of + ": each technique's quality setting was scaled until " +
                    (total ? "its prepare and one frame together" : "one frame") + " took about " + s.str() +
                    " s (within 10 %, at most five tries); a technique without such a setting ran as given." +
                    (total ? " Prepare counts because it is part of the work that makes the image (the photon pass, "
                             "the voxelization)."
                           : " Prepare is left out, as for an animation where it is paid once."));
    }
    return n;
}

// Each image at its native size; a click enlarges it 3× (and back). Every technique's
// image has a button that flips it to the reference in place, the way researchers compare.
constexpr const char* kPageScript = R"(<script>
function flipImage(button) {
  const img = document.getElementById(button.dataset.target);
  const showingReference = img.dataset.showing === 'reference';
  img.src = showingReference ? img.dataset.own : 'reference.png';
  img.dataset.showing = showingReference ? 'own' : 'reference';
  document.getElementById(button.dataset.target + '-caption').textContent =
      showingReference ? img.dataset.label : 'reference (path tracer)';
  button.textContent = showingReference ? 'flip to the reference' : 'flip back to ' + img.dataset.label;
}
document.addEventListener('click', function (event) {
  const img = event.target;
  if (img.tagName !== 'IMG') return;
  img.style.width = img.style.width ? '' : (3 * img.naturalWidth) + 'px';
});
</script>
)";

std::string figure(const std::string& src, const std::string& alt, const std::string& caption) {
    return "<figure><img src=\"" + src + "\" alt=\"" + alt + "\" title=\"click to enlarge\"><figcaption>" + caption +
           "</figcaption></figure>\n";
}

std::string html_page(const CompareReport& r, const ResultTable& table, const std::vector<std::string>& notes) {
    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>gilab compare: " << escape_html(r.scene)
      << "</title>\n<style>body{font-family:sans-serif;margin:1.5em}div.scroll{overflow-x:auto}"
         "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
         "figure{display:inline-block;margin:0 1em 1em 0;vertical-align:top}img{image-rendering:pixelated;"
         "cursor:zoom-in}figcaption{font-size:90%}button{margin:0.3em 0}</style></head><body>\n";
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
    h << "</ul>\n<h2>Images</h2>\n<p>Images at their native size; click one to enlarge it. Each technique's image flips to"
         " the reference in place.</p>\n"
      << figure("reference.png", "reference", "reference (path tracer, " + std::to_string(r.reference_spp) + " spp)");
    for (const auto& e : r.entries) {
        const std::string t = escape_html(e.technique);
        h << "<div><h3>" << t << "</h3>\n"
          << "<figure><img id=\"image-" << t << "\" src=\"" << t << ".png\" alt=\"" << t << "\" data-own=\"" << t
          << ".png\" data-label=\"" << t << "\" data-showing=\"own\" title=\"click to enlarge\"><figcaption><span id=\"image-"
          << t << "-caption\">" << t << "</span><br><button type=\"button\" class=\"flip\" data-target=\"image-" << t
          << "\" onclick=\"flipImage(this)\">flip to the reference</button></figcaption></figure>\n"
          << figure(t + "_flip.png", t + " FLIP", "FLIP (LDR), mean " + escape_html(format_cell(e.flip)))
          << figure(t + "_hdrflip.png", t + " HDR-FLIP", "HDR-FLIP, mean " + escape_html(format_cell(e.hdr_flip)))
          << figure(t + "_ssim.png", t + " 1 − SSIM", "1 − SSIM, SSIM " + escape_html(format_cell(e.ssim))) << "</div>\n";
    }
    h << kPageScript << "</body></html>\n";
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
    if (r.equal_time_seconds) {
        doc["equal_time_seconds"] = *r.equal_time_seconds;
        doc["equal_time_of"] = r.equal_time_of;
    }
    doc["git_revision"] = git_revision();
    doc["machine"] = machine_description();
    doc["notes"] = n;
    nlohmann::json entries = nlohmann::json::array();
    for (const auto& e : r.entries) {
        nlohmann::json exposures = nlohmann::json::array();
        for (const auto& x : e.hdr_flip_exposures)
            exposures.push_back({{"start_stops", x.start}, {"stop_stops", x.stop}, {"count", x.count}});
        entries.push_back({{"technique", e.technique}, {"quality_setting", e.knob}, {"prepare_ms", e.prepare_ms},
                           {"frame_ms", e.frame_ms}, {"prepare_plus_frame_ms", e.prepare_ms + e.frame_ms},
                           {"peak_rss_mib", e.peak_rss_mib}, {"peak_rss_reset", e.peak_rss_exact},
                           {"relmse", e.relmse}, {"ssim", e.ssim}, {"flip", e.flip}, {"hdr_flip", e.hdr_flip},
                           {"hdr_flip_exposures", exposures}, {"settings", e.settings}, {"stats", e.stats},
                           {"files", {e.technique + ".exr", e.technique + ".png", e.technique + "_flip.png",
                                      e.technique + "_hdrflip.png", e.technique + "_ssim.png"}}});
    }
    doc["techniques"] = entries;
    doc["table"] = {{"title", table.title}, {"columns", table.columns}, {"rows", table.rows}};

    std::ostringstream md;
    md << "# gilab compare — " << r.scene << "\n\n" << to_markdown(table) << "\n";
    for (const auto& note : n) md << "- " << note << "\n";
    md << "\nImages: `reference.png` and, per technique, `TECHNIQUE.png` with its heat maps `TECHNIQUE_flip.png`, "
          "`TECHNIQUE_hdrflip.png` and `TECHNIQUE_ssim.png` (1 − SSIM); `index.html` shows them, each technique's image "
          "flipping to the reference in place.\n";

    write_file_atomically(dir / "table.md", md.str());
    write_file_atomically(dir / "index.html", html_page(r, table, n));
    write_file_atomically(dir / "results.json", doc.dump(2) + "\n");
}

std::string comparison_summary(const std::filesystem::path& results_root) {
    namespace fs = std::filesystem;
    const fs::path root = results_root / "compare";
    std::error_code ec;
    if (!fs::is_directory(root, ec)) return "";
    std::vector<fs::path> scenes;
    for (const auto& entry : fs::directory_iterator(root, ec))
        if (entry.is_directory() && entry.path().filename().string().rfind('.', 0) != 0 &&
            fs::exists(entry.path() / "results.json"))
            scenes.push_back(entry.path());
    std::sort(scenes.begin(), scenes.end());
    if (scenes.empty()) return "";

    // technique → "scene: figures" in scene order; techniques in the order first compared.
    std::vector<std::string> order;
    std::map<std::string, std::vector<std::string>> cells;
    std::vector<std::string> problems;
    for (const fs::path& dir : scenes) {
        const std::string scene = dir.filename().string();
        nlohmann::json doc;
        try {
            std::ifstream in(dir / "results.json");
            doc = nlohmann::json::parse(in);
            for (const auto& e : doc.at("techniques")) {
                const std::string t = e.at("technique").get<std::string>();
                if (!cells.count(t)) order.push_back(t);
                std::ostringstream c;
                const double ms = e.at("frame_ms").get<double>();
                c << scene << " ";
                // Whole milliseconds from 100 on (1620 ms, not 1.62e+03 ms); three digits below.
                if (ms >= 100) c << std::llround(ms);
                else c << std::setprecision(3) << ms;
                c << std::setprecision(3) << " ms, relMSE "
                  << e.at("relmse").get<double>() << ", FLIP " << e.at("flip").get<double>();
                cells[t].push_back(c.str());
            }
        } catch (const std::exception& ex) {
            problems.push_back((dir / "results.json").string() + " could not be read: " + ex.what());
        }
    }
    std::ostringstream out;
    out << "comparisons against the path-traced reference (frame time, relMSE, FLIP):\n";
    size_t width = 0;
    for (const auto& t : order) width = std::max(width, t.size());
    for (const auto& t : order) {
        out << "  " << t << std::string(width - t.size(), ' ') << "  ";
        for (size_t i = 0; i < cells[t].size(); ++i) out << (i ? " | " : "") << cells[t][i];
        out << "\n";
    }
    for (const auto& p : problems) out << "  " << p << "\n";
    return out.str();
}

}  // namespace gilab
