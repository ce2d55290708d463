// One libFuzzer harness; GILAB_FUZZ_TARGET names the target (see fuzz_targets.hpp).
// A gilab::Error is the expected answer to a bad input; anything else aborts, so that
// libFuzzer keeps the input as a crash.
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include "tests/fuzz/fuzz_targets.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    gilab::fuzz::initialise();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const gilab::fuzz::Target& target = gilab::fuzz::target(GILAB_FUZZ_TARGET);
    try {
        gilab::fuzz::run_checked(target, data, size);
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "%s\n", e.what());
        std::abort();
    }
    return 0;
}
