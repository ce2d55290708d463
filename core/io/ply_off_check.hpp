#pragma once
// Structural check of a PLY or OFF file before CGAL reads it. CGAL sizes its arrays
// from the counts a file declares, and reads a face's corner count before its corners,
// so one corrupt count makes it allocate gigabytes. Here every count is checked against
// the bytes left in the file and against the memory budget, every number must parse,
// coordinates must be finite and face indices in range. Errors name the file (with the
// line for text files, the byte offset for binary ones), the element and the value.
#include <cstdint>
#include <string>
#include <vector>

namespace gilab {

struct PolygonFileCounts {
    uint64_t vertices = 0;
    uint64_t faces = 0;
    uint64_t corners = 0;  // over all faces
    // OFF only: where the header keyword (e.g. "COFF", "STNOFF") lies in the file, so the
    // loader can hand CGAL a plain "OFF" (length 0 when the file has no keyword).
    size_t off_keyword_offset = 0;
    size_t off_keyword_length = 0;
    // Header lines that are no PLY keyword (free text such as "Created by ..."), which
    // other readers skip: "file:line: ..." notes for the scene's warnings.
    std::vector<std::string> warnings;
};

PolygonFileCounts check_ply(const std::string& bytes, const std::string& file);
PolygonFileCounts check_off(const std::string& bytes, const std::string& file);

}  // namespace gilab
