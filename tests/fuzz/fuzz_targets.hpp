#pragma once
// The loaders and parsers under fuzzing, each as one function of raw bytes. The libFuzzer
// harnesses (tests/fuzz/*_fuzz.cpp) and the regression test (tests/core/io/fuzz_corpus_test)
// call the same functions, so an input the fuzzer found is replayed exactly as found.
//
// A target returns normally when the input loads or is refused with gilab::Error, which
// is the contract for every input. Anything else is a finding: another exception type is
// reported (an "internal error" for the user) and aborts; crashes, leaks and undefined
// behaviour are caught by the sanitizers the harnesses are built with.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gilab::fuzz {

struct Target {
    const char* name;  // "obj", "gltf", "ply_off", "scene_json", "settings"
    void (*run)(const uint8_t* data, size_t size);
};

const std::vector<Target>& targets();
const Target& target(const std::string& name);

// What the harness process needs once: a small memory limit (a corrupt count must be
// refused against it, not allocated) and a scratch folder for the files the loaders read.
void initialise();

// Runs one input through a target. Returns the gilab::Error's message, or "" when the
// input loaded; any other exception becomes std::runtime_error("internal error: ...").
std::string run_checked(const Target& target, const uint8_t* data, size_t size);

// The folder the inputs are written to (one per process).
const std::filesystem::path& scratch_directory();

}  // namespace gilab::fuzz
