// The papers' figures as data (experiments/papers/pN/*.csv, compiled in): every file holds
// exactly the published figures, typed a second time below from the papers' tables in
// their layout as printed (so a typo in a file, or here, shows as a mismatch); every file
// on disk is compiled in, checked here, and parses with numbers where numbers belong; and
// the loader reads quoting, finds rows by key and names what it cannot find.
#include <gtest/gtest.h>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>
#include "core/util/error.hpp"
#include "experiments/runner/paper_figures.hpp"
#include "tests/test_support.hpp"

namespace {

using namespace gilab;
namespace fs = std::filesystem;

using Value = std::variant<double, std::string>;
using Row = std::vector<Value>;

// One file as the paper prints it: its columns in order, the columns that pick a row,
// and every row.
struct Expected {
    std::vector<std::string> columns;
    std::vector<std::string> key;
    std::vector<Row> rows;
};

std::string show(const Value& v) {
    if (const double* d = std::get_if<double>(&v)) {
        std::ostringstream s;
        s << *d;
        return s.str();
    }
    return std::get<std::string>(v);
}

// ---------------------------------------------------------------------------------
// P1 — photon mapping for VR headsets

std::vector<Row> photon_rows(std::initializer_list<std::array<double, 4>> rows) {
    std::vector<Row> out;
    for (const auto& r : rows) out.push_back({r[0], r[1], r[2], r[3]});
    return out;
}

void add_p1(std::map<std::string, Expected>& e) {
    const std::vector<std::string> key = {"photons_side", "radius"};
    e["p1/table1"] = {{"photons_side", "radius", "kd_tree ms", "hash_grid ms"},
                      key,
                      photon_rows({{512, 0.02, 7.28, 3.89},
                                   {512, 0.05, 118.35, 90.74},
                                   {512, 0.1, 426.39, 501.79},
                                   {256, 0.05, 8.32, 5.23},
                                   {256, 0.1, 72.05, 49.29},
                                   {256, 0.2, 287.87, 362.10},
                                   {128, 0.05, 2.57, 1.94},
                                   {128, 0.1, 5.69, 3.67},
                                   {128, 0.2, 36.29, 22.90}})};
    e["p1/table2"] = {{"photons_side", "radius", "with_heap ms", "without_heap ms"},
                      key,
                      photon_rows({{512, 0.02, 3.89, 2.33},
                                   {512, 0.05, 90.74, 4.36},
                                   {512, 0.1, 501.79, 11.43},
                                   {256, 0.05, 5.23, 2.30},
                                   {256, 0.1, 49.29, 3.94},
                                   {256, 0.2, 362.10, 11.24}})};
    e["p1/table3"] = {{"photons_side", "radius", "single_kernel ms", "hybrid_kernel ms"},
                      key,
                      photon_rows({{512, 0.05, 4.59, 3.41},
                                   {512, 0.1, 12.39, 6.52},
                                   {512, 0.2, 37.60, 17.51},
                                   {256, 0.05, 2.60, 2.31},
                                   {256, 0.1, 4.03, 3.76},
                                   {256, 0.2, 10.66, 6.00}})};
    e["p1/table4"] = {{"photons_side", "radius", "without_shared_memory ms", "with_shared_memory ms"},
                      key,
                      photon_rows({{512, 0.05, 3.41, 3.18},
                                   {512, 0.1, 6.52, 6.33},
                                   {512, 0.2, 17.51, 15.88},
                                   {256, 0.05, 2.31, 2.25},
                                   {256, 0.1, 3.76, 3.06},
                                   {256, 0.2, 6.00, 5.80}})};
    e["p1/table5"] = {{"photons_side", "radius", "eyes_separately ms", "stereo_reuse ms"},
                      key,
                      photon_rows({{512, 0.05, 15.22, 13.14},
                                   {512, 0.10, 25.01, 22.30},
                                   {512, 0.15, 33.42, 24.52},
                                   {256, 0.05, 11.19, 11.12},
                                   {256, 0.10, 13.97, 11.19},
                                   {256, 0.15, 16.19, 12.73}})};
    e["p1/fig9_10"] = {{"scene", "photons_side", "radius", "frame ms"},
                       {"scene"},
                       {{"Cornell Box", 512.0, 0.2, 18.38}, {"Office", 512.0, 0.15, 11.96}}};
}

// ---------------------------------------------------------------------------------
// P2 — sparse voxel DAGs, shadow DAG, multi-frame DAG

void add_p2(std::map<std::string, Expected>& e) {
    e["p2/table1"] = {{"scene", "svo nodes (×10⁴)", "svo pointers (×10⁴)", "esvo nodes (×10⁴)", "esvo pointers (×10⁴)",
                       "svdag nodes (×10⁴)", "svdag pointers (×10⁴)"},
                      {"scene"},
                      {{"Bunny", 2307.0, 529.0, 2543.0, 701.0, 17.1, 4.8},
                       {"Buddha", 1577.0, 438.0, 1837.0, 487.0, 145.1, 43.4},
                       {"Dragon", 890.0, 214.0, 221.0, 53.0, 14.2, 3.8}}};
    e["p2/table2"] = {{"scene", "resolution", "svo MB", "esvo MB", "svdag MB"},
                      {"scene", "resolution"},
                      {{"Bunny", 512.0, 5.82, 31.93, 1.06},
                       {"Bunny", 1000.0, 22.42, 123.50, 3.32},
                       {"Buddha", 512.0, 3.49, 36.57, 7.44},
                       {"Buddha", 1000.0, 13.94, 126.60, 26.30},
                       {"Dragon", 512.0, 0.25, 0.47, 0.08},
                       {"Dragon", 1000.0, 0.82, 1.49, 0.31}}};
    {
        // As printed: one line per resolution, t_A / t_B for Bunny, Buddha, Dragon.
        const std::vector<std::pair<double, std::array<double, 6>>> printed = {
            {128, {6.14, 2.29, 8.75, 3.06, 11.36, 4.31}},
            {256, {24.06, 5.07, 33.55, 8.07, 40.25, 11.30}},
            {512, {250, 30, 340, 40, 400, 50}},
            {1000, {1020, 130, 1420, 190, 1600, 220}},
            {2000, {4250, 490, 5800, 780, 6530, 890}}};
        Expected t{{"scene", "resolution", "t_A ms", "t_B ms"}, {"scene", "resolution"}, {}};
        const char* scenes[] = {"Bunny", "Buddha", "Dragon"};
        for (const auto& [res, times] : printed)
            for (int s = 0; s < 3; ++s) t.rows.push_back({scenes[s], res, times[2 * s], times[2 * s + 1]});
        e["p2/table3"] = t;
    }
    {
        // As printed: one line per resolution, S1/S2/S3 for Citadel, Villa, Terrain.
        const std::vector<std::pair<double, std::array<double, 9>>> printed = {
            {1000, {2.30, 0.493, 0.231, 2.30, 0.462, 0.146, 2.30, 0.592, 0.538}},
            {2000, {9.27, 1.62, 0.532, 9.27, 2.47, 0.336, 9.27, 2.37, 2.03}},
            {4000, {37.20, 5.10, 1.23, 37.20, 7.78, 0.772, 37.20, 7.50, 6.64}},
            {16000, {605.72, 47.47, 6.46, 605.72, 85.29, 4.09, 605.72, 91.20, 81.59}},
            {32000, {2422, 127.14, 13.87, 2422, 249.04, 9.40, 2422, 183.23, 163.92}}};
        Expected t{{"scene", "resolution", "S1 MB", "S2 MB", "S3 MB"}, {"scene", "resolution"}, {}};
        const char* scenes[] = {"Citadel", "Villa", "Terrain"};
        for (const auto& [res, mb] : printed)
            for (int s = 0; s < 3; ++s) t.rows.push_back({scenes[s], res, mb[3 * s], mb[3 * s + 1], mb[3 * s + 2]});
        e["p2/table4"] = t;
    }
    e["p2/table5"] = {{"scene", "svo N_p (×10³)", "svo N_n (×10⁶)", "difference_tree N_p (×10³)",
                       "difference_tree N_n (×10⁶)", "svdag N_p (×10³)", "svdag N_n (×10⁶)",
                       "time_correlated N_p (×10³)", "time_correlated N_n (×10⁶)"},
                      {"scene"},
                      {{"Kitchen", 873.0, 685.0, 15.1, 1.71, 94.8, 6.87, 5.82, 0.36},
                       {"Robot", 321.0, 68.7, 224.0, 56.6, 50.7, 10.0, 29.3, 7.28},
                       {"Fire", 593.0, 192.0, 433.0, 158.0, 62.1, 20.8, 44.0, 13.66}}};
    {
        // As printed: V_1 / V_2 / V_3 at 1024×768, 800×600, 400×300.
        const std::vector<std::pair<std::string, std::array<double, 3>>> printed = {
            {"Kitchen", {21.3, 28.1, 62.9}}, {"Robot", {12.0, 16.1, 53.4}}, {"Fire", {6.20, 9.90, 27.1}}};
        const char* images[] = {"1024×768", "800×600", "400×300"};
        Expected t{{"scene", "image (pixels)", "fps"}, {"scene", "image (pixels)"}, {}};
        for (const auto& [scene, fps] : printed)
            for (int i = 0; i < 3; ++i) t.rows.push_back({scene, images[i], fps[i]});
        e["p2/table6"] = t;
    }
    // Kämpe et al. 2016, cited beside Table 5: one sequence, its grid, frames and size.
    e["p2/table5_kampe2016"] = {{"sequence", "resolution (voxels/axis)", "frames", "MB"},
                                {"sequence"},
                                {{"captured performer", 2048.0, 70.0, 1.86}}};
    e["p2/fig13"] = {{"structures", "time ratio"}, {"structures"}, {{"SVO, ESVO, SVDAG", "≈ 1 (about equal)"}}};
    e["p2/fig16_18"] = {{"scene", "structure", "mean vs shadow map (%)"},
                        {"scene", "structure"},
                        {{"Citadel", "S3", -67.9}}};
}

// ---------------------------------------------------------------------------------
// P3 — cascaded voxel cone tracing

const std::vector<std::string> kStructures = {"3D texture", "SVO", "MSVO", "SVDAG", "cascaded"};

// A structure table as printed: per structure, the figures of each scene at the two
// resolutions, scenes in the paper's column order.
Expected structure_table(const std::string& quantity, const std::vector<std::string>& scenes,
                         std::array<double, 2> resolutions, const std::vector<std::vector<double>>& by_structure) {
    Expected t{{"scene", "resolution", "structure", quantity}, {"scene", "resolution", "structure"}, {}};
    for (size_t s = 0; s < kStructures.size(); ++s) {
        EXPECT_EQ(by_structure[s].size(), 2 * scenes.size()) << quantity << ", " << kStructures[s];
        for (size_t c = 0; c < scenes.size(); ++c)
            for (size_t r = 0; r < 2; ++r)
                t.rows.push_back({scenes[c], resolutions[r], kStructures[s], by_structure[s].at(2 * c + r)});
    }
    return t;
}

void add_p3(std::map<std::string, Expected>& e) {
    const std::vector<std::string> stanford = {"Bunny", "Dragon", "Buddha"};
    const std::vector<std::string> dynamic = {"Sponza", "Sibenik"};
    // Tables 1 and 2, voxels (×10⁶). Dragon's SVDAG at 128³ is printed 0.891 (sic).
    e["p3/table1"] = structure_table("voxels (×10⁶)", stanford, {128, 256},
                                     {{2.097, 16.78, 2.097, 16.78, 2.097, 16.78},
                                      {0.189, 3.604, 0.113, 2.364, 0.166, 3.215},
                                      {0.176, 3.455, 0.101, 2.178, 0.151, 2.986},
                                      {0.133, 2.562, 0.891, 1.855, 0.125, 2.411},
                                      {0.098, 0.131, 0.098, 0.131, 0.131, 0.164}});
    e["p3/table2"] = structure_table("voxels (×10⁶)", dynamic, {256, 512},
                                     {{16.78, 134.2, 16.78, 134.2},
                                      {3.135, 6.032, 2.916, 5.489},
                                      {2.885, 5.766, 2.598, 5.247},
                                      {2.445, 4.705, 2.225, 4.282},
                                      {0.131, 0.164, 0.131, 0.164}});
    // Tables 3 and 4, voxelization time (ms).
    e["p3/table3"] = structure_table("voxelize ms", stanford, {128, 256},
                                     {{14.96, 43.22, 15.36, 42.75, 16.16, 45.65},
                                      {56.17, 96.41, 46.81, 80.34, 60.85, 104.4},
                                      {53.26, 92.34, 44.29, 76.67, 58.54, 101.3},
                                      {62.71, 135.51, 53.24, 109.44, 72.86, 166.0},
                                      {5.179, 6.872, 4.316, 5.727, 5.611, 7.445}});
    e["p3/table4"] = structure_table("voxelize ms", dynamic, {256, 512},
                                     {{51.29, 230.1, 52.11, 233.8},
                                      {88.48, 280.8, 98.19, 314.5},
                                      {86.96, 275.4, 96.78, 309.7},
                                      {105.1, 336.3, 115.1, 384.4},
                                      {6.889, 8.549, 7.716, 9.575}});
    // Tables 5 and 6, memory (MB as printed).
    e["p3/table5"] = structure_table("memory MB", stanford, {128, 256},
                                     {{2, 16, 2, 16, 2, 16},
                                      {1.584, 12.67, 1.32, 10.56, 1.726, 13.21},
                                      {1.679, 13.44, 1.79, 11.98, 1.878, 14.43},
                                      {0.951, 7.602, 0.924, 3.392, 1.295, 9.247},
                                      {0.56, 0.75, 0.56, 0.75, 0.56, 0.75}});
    e["p3/table6"] = structure_table("memory MB", dynamic, {256, 512},
                                     {{16, 128, 16, 128},
                                      {6.06, 48.48, 6.908, 54.29},
                                      {7.07, 50.87, 7.106, 56.86},
                                      {4.545, 35.98, 5.388, 43.35},
                                      {0.75, 0.94, 0.75, 0.94}});
    e["p3/table7"] = {{"phase", "VXGI ms", "cascaded ms"},
                      {"phase"},
                      {{"rasterize", 1.0, 1.0},
                       {"light injection", 16.5, 12.1},
                       {"direct lighting", 3.0, 1.8},
                       {"diffuse", 9.2, 6.5},
                       {"specular", 8.0, 5.2},
                       {"total", 36.7, 26.5},
                       {"dynamic update", 15.5, 2.0}}};
    e["p3/fig9"] = {{"curve", "finding"},
                    {"curve"},
                    {{"VXGI", "VXGI ≈ 10 fps below cascaded + strategy"},
                     {"cascaded with update strategy", "fastest; update ≈ 2.0 ms vs VXGI 15.5 ms"},
                     {"cascaded without update strategy", "slightly faster than VXGI"},
                     {"PM", "PM (and LPV) 5–20 fps"},
                     {"LPV", "PM (and LPV) 5–20 fps"},
                     {"update time VXGI / cascaded", "15.5 / 2.0 = 7.8 (VXGI vs cascaded)"}}};
    e["p3/fig10"] = {{"curve", "memory over VXGI"}, {"curve"}, {{"VXGI", 1.0}, {"cascaded", 0.4}}};
}

const std::map<std::string, Expected>& expected_files() {
    static const std::map<std::string, Expected> all = [] {
        std::map<std::string, Expected> e;
        add_p1(e);
        add_p2(e);
        add_p3(e);
        return e;
    }();
    return all;
}

fs::path papers_dir() { return fs::path(GILAB_SOURCE_DIR) / "experiments" / "papers"; }

// Every CSV under experiments/papers, by name ("p1/table1").
std::map<std::string, fs::path> files_on_disk() {
    std::map<std::string, fs::path> files;
    for (const auto& entry : fs::recursive_directory_iterator(papers_dir())) {
        if (!entry.is_regular_file() || entry.path().extension() != ".csv") continue;
        fs::path relative = fs::relative(entry.path(), papers_dir());
        relative.replace_extension();
        files[relative.generic_string()] = entry.path();
    }
    return files;
}

std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

template <class Map>
std::set<std::string> names_of(const Map& m) {
    std::set<std::string> names;
    for (const auto& [name, value] : m) names.insert(name);
    return names;
}

// ---------------------------------------------------------------------------------

TEST(PaperFigures, EveryFileOnDiskIsCompiledInAndCheckedHere) {
    const std::set<std::string> on_disk = names_of(files_on_disk());
    const std::vector<std::string> compiled = paper_figure_names();
    EXPECT_EQ(std::set<std::string>(compiled.begin(), compiled.end()), on_disk)
        << "the compiled-in files differ from experiments/papers (rebuild?)";
    EXPECT_EQ(names_of(expected_files()), on_disk) << "a file is not checked here, or a checked file is missing";
}

TEST(PaperFigures, CompiledInTextIsTheFileOnDisk) {
    for (const auto& [name, path] : files_on_disk()) {
        const PaperFigures parsed = PaperFigures::parse(name, read(path));
        const PaperFigures& compiled = paper_figures(name);
        EXPECT_EQ(compiled.columns(), parsed.columns()) << name;
        ASSERT_EQ(compiled.rows().size(), parsed.rows().size()) << name;
        for (size_t i = 0; i < parsed.rows().size(); ++i)
            for (const std::string& c : parsed.columns())
                EXPECT_EQ(compiled.rows()[i].text(c), parsed.rows()[i].text(c)) << name << " row " << i << ", " << c;
    }
}

TEST(PaperFigures, EveryFileCitesItsTableAndEveryColumnIsAllNumbersOrAllText) {
    for (const auto& [name, path] : files_on_disk()) {
        const PaperFigures f = PaperFigures::parse(name, read(path));  // throws on a bad field count or quote
        std::string paper = name.substr(0, 2);  // "p1/table1" cites "P1 ..."
        paper[0] = 'P';
        paper += ' ';
        EXPECT_EQ(f.comment().rfind(paper, 0), 0u) << name << ": the first line should cite the table: # " << paper << "...";
        EXPECT_FALSE(f.rows().empty()) << name;
        for (const std::string& c : f.columns()) {
            size_t numbers = 0;
            for (const PaperRow& r : f.rows()) numbers += r.cell(c).number.has_value();
            EXPECT_TRUE(numbers == 0 || numbers == f.rows().size())
                << name << ", column '" << c << "': " << numbers << " of " << f.rows().size()
                << " cells are numbers (a typo such as '4,282'?)";
        }
    }
}

TEST(PaperFigures, EveryFileHoldsThePublishedFigures) {
    for (const auto& [name, expected] : expected_files()) {
        SCOPED_TRACE(name);
        const PaperFigures* f = nullptr;
        ASSERT_NO_THROW(f = &paper_figures(name));
        EXPECT_EQ(f->columns(), expected.columns);
        EXPECT_EQ(f->rows().size(), expected.rows.size());
        for (const Row& row : expected.rows) {
            ASSERT_EQ(row.size(), expected.columns.size());
            PaperKeys key;
            std::string described;
            for (const std::string& k : expected.key) {
                const size_t i = size_t(std::find(expected.columns.begin(), expected.columns.end(), k) - expected.columns.begin());
                described += k + "=" + show(row.at(i)) + " ";
                if (const double* d = std::get_if<double>(&row[i])) key.emplace_back(k, *d);
                else key.emplace_back(k, std::get<std::string>(row[i]));
            }
            const PaperRow* r = f->find(key);
            ASSERT_NE(r, nullptr) << "no row " << described;
            for (size_t i = 0; i < expected.columns.size(); ++i) {
                const std::string& c = expected.columns[i];
                if (const double* d = std::get_if<double>(&row[i])) {
                    ASSERT_TRUE(r->cell(c).number.has_value()) << described << c << ": '" << r->text(c) << "'";
                    EXPECT_EQ(r->number(c), *d) << described << c << ": file '" << r->text(c) << "'";
                } else {
                    EXPECT_EQ(r->text(c), std::get<std::string>(row[i])) << described << c;
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// The loader

TEST(PaperFiguresLoader, AnUnknownNameIsAnErrorNamingIt) {
    const std::string message = test::error_of([] { (void)paper_figures("p9/table42"); });
    EXPECT_NE(message.find("p9/table42"), std::string::npos) << message;
    EXPECT_NE(message.find("p1/table1"), std::string::npos) << "should list the files there are: " << message;
}

TEST(PaperFiguresLoader, ReadsQuotedFieldsCommentsAndNumbers) {
    const PaperFigures f = PaperFigures::parse("x/quoted", "# X Table 1: a test\n# second line\r\n"
                                                           "name,\"ms, median\",note\r\n"
                                                           "\"a, b\",1.5,\"said \"\"hi\"\"\"\n"
                                                           "c,-2,\n\n");
    EXPECT_EQ(f.comment(), "X Table 1: a test\nsecond line");
    EXPECT_EQ(f.columns(), (std::vector<std::string>{"name", "ms, median", "note"}));
    ASSERT_EQ(f.rows().size(), 2u);
    EXPECT_EQ(f.rows()[0].text("name"), "a, b");
    EXPECT_EQ(f.rows()[0].number("ms, median"), 1.5);
    EXPECT_EQ(f.rows()[0].text("note"), "said \"hi\"");
    EXPECT_FALSE(f.rows()[0].cell("name").number);
    EXPECT_EQ(f.rows()[1].integer("ms, median"), -2);
    EXPECT_EQ(f.rows()[1].text("note"), "");
    EXPECT_EQ(f.rows()[1].line(), 5);
}

TEST(PaperFiguresLoader, MalformedFilesAreErrorsNamingTheLine) {
    auto error = [](const std::string& text) { return test::error_of([&] { (void)PaperFigures::parse("x/bad", text); }); };
    EXPECT_NE(error("a,b\n1,2\n3\n").find("x/bad.csv:3"), std::string::npos);
    EXPECT_NE(error("a,b\n1,2,3\n").find("3 fields, the header has 2"), std::string::npos);
    EXPECT_NE(error("a,b\n\"1,2\n").find("not closed"), std::string::npos);
    EXPECT_NE(error("a,b\n1\"x,2\n").find("quote inside"), std::string::npos);
    EXPECT_NE(error("a,b\n\"1\"x,2\n").find("after the closing quote"), std::string::npos);
    EXPECT_NE(error("a,a\n1,2\n").find("named twice"), std::string::npos);
    EXPECT_NE(error("a,b\n1,2\n\n3,4\n").find("empty line"), std::string::npos);
    EXPECT_NE(error("# only a comment\n").find("no header"), std::string::npos);
}

TEST(PaperFiguresLoader, FindsRowsByKeyAndNamesWhatItCannotFind) {
    const PaperFigures f = PaperFigures::parse("x/keys", "scene,resolution,ms\nBunny,128,6.14\nBunny,256,24.06\n"
                                                         "Dragon,128,11.36\nDragon,128,12\n");
    EXPECT_EQ(f.row({{"scene", "Bunny"}, {"resolution", 256}}).number("ms"), 24.06);
    EXPECT_EQ(f.row({{"scene", "Bunny"}, {"resolution", 256.0}}).line(), 3);
    EXPECT_EQ(f.find({{"scene", "Bunny"}, {"resolution", 512}}), nullptr);
    EXPECT_EQ(f.rows_where({{"scene", "Bunny"}}).size(), 2u);
    const std::string missing = test::error_of([&] { (void)f.row({{"scene", "Buddha"}, {"resolution", 128}}); });
    EXPECT_NE(missing.find("x/keys.csv"), std::string::npos) << missing;
    EXPECT_NE(missing.find("scene = Buddha, resolution = 128"), std::string::npos) << missing;
    EXPECT_NE(test::error_of([&] { (void)f.find({{"scene", "Dragon"}}); }).find("2 rows"), std::string::npos);
    EXPECT_NE(test::error_of([&] { (void)f.find({{"res", 128}}); }).find("no column 'res'"), std::string::npos);
    const PaperRow& r = f.row({{"scene", "Bunny"}, {"resolution", 128}});
    EXPECT_NE(test::error_of([&] { (void)r.number("scene"); }).find("x/keys.csv:2: column 'scene' holds 'Bunny'"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { (void)r.number("fps"); }).find("no column 'fps'"), std::string::npos);
    EXPECT_NE(test::error_of([&] { (void)r.integer("ms"); }).find("not an integer"), std::string::npos);
}

TEST(PaperFiguresLoader, ScaledNumbersAreTheDecimalLiteral) {
    const PaperFigures f = PaperFigures::parse("x/scaled", "a,b,c\n0.36,13.66,1e3\n");
    const PaperRow& r = f.rows()[0];
    EXPECT_EQ(r.scaled("a", 6), 0.36e6);
    EXPECT_EQ(r.scaled("b", 6), 13.66e6);
    EXPECT_EQ(r.scaled("b", -3), 13.66e-3);
    EXPECT_NE(test::error_of([&] { (void)r.scaled("c", 3); }).find("already has an exponent"), std::string::npos);
}

}  // namespace
