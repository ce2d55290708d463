#pragma once
// Checks of OBJ and MTL text before tinyobjloader reads them. tinyobjloader reads an
// unparsable number as 0, an index beyond 32 bits as whatever its overflow gives, and
// skips bad faces with only a warning; here every vertex coordinate, face index and MTL
// colour is checked first and reported with its file and line.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gilab {

struct ObjScan {
    std::vector<uint32_t> face_lines;  // line number of every face, in file order
    uint64_t vertices = 0, normals = 0, texcoords = 0, corners = 0;
    std::vector<std::filesystem::path> material_libraries;  // mtllib files that exist, resolved
};

// `text` is the whole OBJ file. Throws Error "file:line: ..." for a malformed vertex or
// face line, UTF-16 text or an index that cannot be one; checks the memory that
// loading will take against the budget.
ObjScan scan_obj(const std::filesystem::path& path, const std::string& text);

// Kd/Ka/Ks/Ke/Tf colours and Ns/Ni/d/Tr scalars must be finite numbers.
void check_mtl(const std::filesystem::path& path);

}  // namespace gilab
