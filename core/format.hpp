#pragma once
// Numbers written into messages and file headers: 9 significant digits, enough to
// round-trip a float and short for round values ("0.05", not "0.0500000007").
#include <sstream>
#include <string>

namespace gilab {

inline std::string format_number(double v) {
    std::ostringstream out;
    out.precision(9);
    out << v;
    return out.str();
}

}  // namespace gilab
