#pragma once
// One exception type for every kind of bad input. The message names where the problem
// is (file, file:line, or a JSON path) and what is wrong, so the CLI can print it as is.
#include <stdexcept>
#include <string>

namespace gilab {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& what) : std::runtime_error(what) {}
    // "location: what" — location is a file path, "file:line" or a settings key path.
    Error(const std::string& location, const std::string& what)
        : std::runtime_error(location.empty() ? what : location + ": " + what) {}
};

}  // namespace gilab
