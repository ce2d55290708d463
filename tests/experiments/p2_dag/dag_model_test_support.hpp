#pragma once
// What the tests of the experiments over P2's models and the whole scenes share: the
// registry, a row's number, and the meshes whose absence skips them.
#include <gtest/gtest.h>
#include <string>
#include "experiments/runner/experiment.hpp"
#include "tests/experiment_test_support.hpp"
#include "tests/test_support.hpp"

namespace gilab::test {

inline const ExperimentRegistry& dag_registry() {
    static const ExperimentRegistry registry = registry_with({register_dag_experiments});
    return registry;
}

inline double num(const nlohmann::json& row, const std::string& column) {
    EXPECT_TRUE(row.contains(column) && row.at(column).is_number()) << "no number in " << column << ": " << row.dump();
    return row.contains(column) && row.at(column).is_number() ? row.at(column).get<double>() : 0.0;
}

// The first of the seven models' meshes missing from the shared scenes ("" when none is).
inline std::string missing_model_mesh() {
    for (const char* mesh : {"bunny/stanford-bunny.obj", "buddha/buddha.obj", "dragon/dragon.obj",
                             "castle/fincastel.obj", "sponza/sponza.obj", "sibenik/sibenik.obj",
                             "conference/conference.obj"})
        if (!shared_asset(mesh)) return mesh;
    return "";
}

}  // namespace gilab::test
