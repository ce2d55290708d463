#include "experiments/html_report.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include "core/error.hpp"
#include "core/image_io.hpp"
#include "experiments/result_writers.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

std::string escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

void write_table(std::ostringstream& html, const nlohmann::json& table) {
    html << "<h3>" << escape(table.value("title", std::string())) << "</h3>\n<table>\n<tr>";
    std::vector<std::string> columns = table["columns"].get<std::vector<std::string>>();
    for (const auto& c : columns)
        html << "<th" << (c.rfind("paper", 0) == 0 ? " class=\"paper\"" : "") << ">" << escape(c) << "</th>";
    html << "</tr>\n";
    for (const auto& row : table["rows"]) {
        html << "<tr>";
        for (const auto& c : columns)
            html << "<td" << (c.rfind("paper", 0) == 0 ? " class=\"paper\"" : "") << ">"
                 << escape(row.contains(c) ? format_cell(row[c]) : "") << "</td>";
        html << "</tr>\n";
    }
    html << "</table>\n";
}

}  // namespace

int write_html_report(const fs::path& results_root) {
    std::vector<fs::path> documents;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(results_root, ec))
        // Hidden folders are runs in progress (or interrupted), not results.
        if (entry.path().filename().string().rfind(".", 0) != 0 && fs::exists(entry.path() / "results.json"))
            documents.push_back(entry.path() / "results.json");
    if (documents.empty()) throw Error(results_root.string(), "no results/*/results.json found (run `gilab experiment` first)");
    std::sort(documents.begin(), documents.end());

    std::ostringstream html;
    html << "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>gilab results</title>\n"
         << "<style>body{font-family:sans-serif;max-width:1200px;margin:2em auto}table{border-collapse:collapse;"
            "margin-bottom:1em}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
            "th.paper,td.paper{background:#eef}img{max-width:100%}</style></head><body>\n"
         << "<h1>gilab results</h1>\n<p>Shaded columns hold the papers' published figures (their hardware); all "
            "other figures were measured by the runs listed.</p>\n";
    for (const auto& path : documents) {
        std::ifstream in(path);
        nlohmann::json doc;
        try {
            doc = nlohmann::json::parse(in);
        } catch (const nlohmann::json::exception& e) {
            throw Error(path.string(), std::string("malformed results file: ") + e.what());
        }
        std::string name = doc.value("experiment", path.parent_path().filename().string());
        html << "<h2 id=\"" << escape(name) << "\">" << escape(name) << "</h2>\n<p>" << escape(doc.value("description", std::string()))
             << "<br>revision " << escape(doc.value("git_revision", std::string("?"))) << ", seed " << doc.value("seed", 0)
             << (doc.value("quick", false) ? ", <b>quick run</b>" : "") << ", "
             << escape(doc["machine"].value("cpu", std::string("unknown CPU"))) << "</p>\n";
        for (const auto& table : doc["tables"]) write_table(html, table);
        if (doc.contains("notes") && !doc["notes"].empty()) {
            html << "<ul>";
            for (const auto& n : doc["notes"]) html << "<li>" << escape(n.get<std::string>()) << "</li>";
            html << "</ul>\n";
        }
        for (const auto& f : doc.value("files", nlohmann::json::array())) {
            std::string file = f.get<std::string>();
            std::string extension = fs::path(file).extension().string();
            if (extension == ".png" || extension == ".svg")
                html << "<figure><img src=\"" << escape(name + "/" + file) << "\"><figcaption>" << escape(file)
                     << "</figcaption></figure>\n";
        }
    }
    html << "</body></html>\n";
    write_file_atomically(results_root / "report.html", html.str());
    return int(documents.size());
}

}  // namespace gilab
