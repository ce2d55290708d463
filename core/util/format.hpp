#pragma once
// Numbers written into messages and file headers.
#include <charconv>
#include <sstream>
#include <string>
#include <string_view>

namespace gilab {

// The values with `separator` between them: join({"a", "b"}) is "a, b".
template <class Range>
std::string join(const Range& values, std::string_view separator = ", ") {
    std::string out;
    bool first = true;
    for (const auto& v : values) {
        if (!first) out += separator;
        out += v;
        first = false;
    }
    return out;
}

// 9 significant digits, enough to round-trip a float and short for round values
// ("0.05", not "0.0500000007"); for computed values in headers and reports.
inline std::string format_number(double v) {
    std::ostringstream out;
    out.precision(9);
    out << v;
    return out.str();
}

// The shortest text that reads back as exactly `v` (std::to_chars): a value quoted in
// an error message reads as it was given — "1e-300", not "0.000000" (std::to_string)
// or "1e-300" rounded to a few digits; "0.1", not "0.100000001". The float overload
// is for values already stored in single precision.
inline std::string number_as_given(double v) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return ec == std::errc() ? std::string(buffer, end) : format_number(v);
}

inline std::string number_as_given(float v) {
    char buffer[32];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return ec == std::errc() ? std::string(buffer, end) : format_number(double(v));
}

}  // namespace gilab
