#pragma once
// Running another program (sbatch, squeue, sacct) and reading what it printed.
#include <string>
#include <vector>

namespace gilab {

struct ProgramResult {
    int exit_code = -1;   // 127 when it could not be started
    std::string output;   // stdout and stderr together
};

// Runs args[0] (looked up on PATH) with the rest as its arguments; no shell between.
ProgramResult call_program(const std::vector<std::string>& args);

// Whether `name` is an executable file in a directory on PATH.
bool program_on_path(const std::string& name);

}  // namespace gilab
