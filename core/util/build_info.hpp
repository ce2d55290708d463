#pragma once
// Facts fixed when the build was configured: the source tree it was built from and its
// git revision. They live in one generated file (build_info.cpp.in) rather than in
// compile definitions, so a new revision or another checkout recompiles one file, not
// every file that includes a core header.
namespace gilab {

const char* build_source_directory();  // the source tree's absolute path
const char* build_git_revision();      // short revision, or "unknown" outside git

}  // namespace gilab
