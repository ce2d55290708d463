#pragma once
// The papers' published tables and figures as data. Each table or figure an experiment
// compares with is one file, experiments/papers/pN/NAME.csv (P1 photon mapping, P2 sparse
// voxel DAGs, P3 cascaded voxel cone tracing), compiled into the library at build time
// (paper_figures.cmake), so the gilab program and the Python module have them wherever
// they run. paper_figures("p1/table1") gives one file's rows; a row maps each column to
// its cell: the text as written and, when the text is a number, that number. Experiments
// take their "paper …" columns from here, never from constants of their own.
//
// File format: leading comment lines starting with '#' (citing the table), one header
// line naming the columns (with the paper's units, e.g. "kd_tree ms"), then one line per
// row with as many fields as the header. Fields are separated by commas; a field holding a
// comma or a quote is quoted ("SVO, ESVO"; "" inside quotes is one quote).
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace gilab {

struct PaperCell {
    std::string text;
    std::optional<double> number;  // when the whole text is a decimal number
};

// One key column and the value it must hold: text compared as text, a number as a number
// (the cell "0.10" matches 0.1).
struct PaperKey {
    PaperKey(std::string column, std::string text) : column(std::move(column)), value(std::move(text)) {}
    PaperKey(std::string column, const char* text) : column(std::move(column)), value(std::string(text)) {}
    PaperKey(std::string column, double number) : column(std::move(column)), value(number) {}
    PaperKey(std::string column, int number) : column(std::move(column)), value(double(number)) {}
    PaperKey(std::string column, unsigned number) : column(std::move(column)), value(double(number)) {}
    std::string column;
    std::variant<std::string, double> value;
    std::string describe() const;  // "column = value"
};
using PaperKeys = std::vector<PaperKey>;

class PaperRow {
public:
    PaperRow(std::string file, int line, std::map<std::string, PaperCell> cells)
        : file_(std::move(file)), line_(line), cells_(std::move(cells)) {}
    const std::map<std::string, PaperCell>& cells() const { return cells_; }
    // An unknown column, or a cell that is not a number, is an Error naming the file, its
    // line and the column.
    const PaperCell& cell(const std::string& column) const;
    const std::string& text(const std::string& column) const { return cell(column).text; }
    double number(const std::string& column) const;
    int integer(const std::string& column) const;  // a number without a fraction
    // The cell's number times 10^exponent, scaled in decimal before it is rounded to a
    // double: "0.36" at exponent 6 gives exactly the double of 0.36e6 (a table printed in
    // units of 10⁶, multiplied out without a second rounding).
    double scaled(const std::string& column, int exponent) const;
    bool matches(const PaperKeys& key) const;
    const std::string& file() const { return file_; }
    int line() const { return line_; }

private:
    std::string where() const;
    std::string file_;
    int line_;
    std::map<std::string, PaperCell> cells_;
};

class PaperFigures {
public:
    // Parses one file's text; a malformed file is an Error naming `name` and the line.
    static PaperFigures parse(const std::string& name, std::string_view text);

    const std::string& name() const { return name_; }            // "p1/table1"
    const std::string& comment() const { return comment_; }      // the '#' lines, without '#'
    const std::vector<std::string>& columns() const { return columns_; }
    const std::vector<PaperRow>& rows() const { return rows_; }
    bool has_column(const std::string& column) const;

    // The row whose key columns hold the key's values: nullptr when there is none (a
    // size the paper did not measure), an Error when several match or a key column is
    // not in the file.
    const PaperRow* find(const PaperKeys& key) const;
    // As find, and an Error naming the file and the key when no row matches.
    const PaperRow& row(const PaperKeys& key) const;
    // Every row matching the key, in file order.
    std::vector<const PaperRow*> rows_where(const PaperKeys& key) const;

private:
    void check_key(const PaperKeys& key) const;
    std::string name_;
    std::string comment_;
    std::vector<std::string> columns_;
    std::vector<PaperRow> rows_;
};

// The file experiments/papers/NAME.csv as compiled in ("p1/table1"); an unknown name is an
// Error naming it and the files there are.
const PaperFigures& paper_figures(const std::string& name);
// Every compiled-in file's name, sorted.
std::vector<std::string> paper_figure_names();

namespace detail {
// One file as embedded by the generated paper_figure_files.cpp.
struct EmbeddedPaperFile {
    const char* name;  // path under experiments/papers without ".csv"
    const unsigned char* data;
    size_t size;
};
std::span<const EmbeddedPaperFile> embedded_paper_files();
}  // namespace detail

}  // namespace gilab
