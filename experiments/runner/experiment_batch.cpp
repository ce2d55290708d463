#include "experiments/runner/experiment_batch.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include "core/util/error.hpp"
#include "core/util/format.hpp"
#include "core/util/parallel.hpp"
#include "experiments/runner/result_writers.hpp"

namespace gilab {

namespace fs = std::filesystem;

namespace {

// What the signal handler prints, rewritten before each experiment starts. The handler
// may run at any moment, so it reads fixed buffers, never a std::string: the text is
// written into the buffer not in use, then published by one atomic store.
struct InterruptionMessage {
    char text[8192];
    size_t length = 0;
};
InterruptionMessage interruption_messages[2];
std::atomic<const InterruptionMessage*> interruption_message{nullptr};

void set_interruption_message(const std::string& text) {
    InterruptionMessage& spare = interruption_message.load() == &interruption_messages[0] ? interruption_messages[1]
                                                                                            : interruption_messages[0];
    spare.length = std::min(text.size(), sizeof spare.text);
    std::memcpy(spare.text, text.data(), spare.length);
    interruption_message.store(&spare);
}

// Async-signal-safe: write(2) and _exit(2) only. The staging folder of the experiment in
// flight stays behind, hidden; the next batch removes it.
extern "C" void stop_on_signal(int signal_number) {
    if (const InterruptionMessage* message = interruption_message.load()) {
        ssize_t ignored = write(STDERR_FILENO, message->text, message->length);
        (void)ignored;
    }
    _exit(128 + signal_number);
}

class SignalHandlers {
public:
    SignalHandlers() {
        struct sigaction action {};
        action.sa_handler = stop_on_signal;
        sigemptyset(&action.sa_mask);
        sigaction(SIGINT, &action, &previous_int_);
        sigaction(SIGTERM, &action, &previous_term_);
    }
    ~SignalHandlers() {
        sigaction(SIGINT, &previous_int_, nullptr);
        sigaction(SIGTERM, &previous_term_, nullptr);
    }
    SignalHandlers(const SignalHandlers&) = delete;
    SignalHandlers& operator=(const SignalHandlers&) = delete;

private:
    struct sigaction previous_int_ {};
    struct sigaction previous_term_ {};
};

std::string list_names(const std::vector<std::string>& names) {
    return names.empty() ? "none" : join(names);
}

std::string describe_interruption(const ExperimentBatch& batch, const std::vector<std::string>& kept,
                                  const std::string& running) {
    const std::string what = running.empty() ? "\ngilab: interrupted" : "\ngilab: interrupted during " + running + "; nothing of it was written";
    return what + ". Kept " +
           std::to_string(kept.size()) + " finished experiment(s) in " + batch.results_root.string() + ": " +
           list_names(kept) + ". Run the same command with --resume to skip them.\n";
}

int resolved_threads(int threads) { return threads > 0 ? threads : int(default_thread_count()); }

}  // namespace

// An exchange when an older run is there (then removed), a rename otherwise.
void publish_directory(const fs::path& staging, const fs::path& final_dir) {
    std::error_code ec;
    if (fs::exists(final_dir, ec)) {
        if (renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, final_dir.c_str(), RENAME_EXCHANGE) != 0)
            throw Error(final_dir.string(), std::string("cannot replace the previous results: ") + std::strerror(errno));
        fs::remove_all(staging, ec);  // now the previous run
    } else if (std::rename(staging.c_str(), final_dir.c_str()) != 0) {
        throw Error(final_dir.string(), std::string("cannot move the results into place: ") + std::strerror(errno));
    }
}

fs::path staging_directory(const fs::path& results_root, const std::string& name) {
    return results_root / ("." + name + ".partial");
}

std::string reason_to_rerun(const Experiment& experiment, const fs::path& experiment_dir, bool quick, uint64_t seed,
                            int threads) {
    const fs::path file = experiment_dir / "results.json";
    std::ifstream in(file);
    if (!in) return "no finished run";
    nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!doc.is_object()) return "results.json is unreadable";
    if (doc.value("git_revision", std::string()) != git_revision())
        return "finished by revision " + doc.value("git_revision", std::string("?")) + ", this is " + git_revision();
    if (doc.value("quick", !quick) != quick) return quick ? "finished without --quick" : "finished with --quick";
    if (doc.value("seed", seed + 1) != seed) return "finished with another seed";
    if (doc.value("threads", -1) != resolved_threads(threads)) return "finished with another thread count";
    if (doc.contains("config") && doc["config"].contains("effective") &&
        !doc["config"]["effective"].value("tasks_missing", nlohmann::json::array()).empty())
        return "merged from some of its tasks only";
    if (experiment.spec && doc.contains("config")) {
        nlohmann::json spec = doc["config"];
        spec.erase("effective");
        if (spec != experiment.spec->to_json()) return "finished with another spec (other --axis values, say)";
    }
    return "";
}

int run_experiment_batch(const ExperimentBatch& batch, std::ostream& out, std::ostream& err) {
    fs::create_directories(batch.results_root);
    SignalHandlers handlers;
    std::vector<std::string> kept;
    int failures = 0;
    for (size_t i = 0; i < batch.experiments.size(); ++i) {
        const Experiment* e = batch.experiments[i];
        // Until the next experiment starts, a signal interrupts that one.
        const std::string next = i + 1 < batch.experiments.size() ? batch.experiments[i + 1]->name : "";
        const fs::path final_dir = batch.results_root / e->name;
        const fs::path staging = staging_directory(batch.results_root, e->name);
        std::error_code ec;
        fs::remove_all(staging, ec);  // left by an interrupted batch
        if (batch.resume) {
            const std::string reason = reason_to_rerun(*e, final_dir, batch.quick, batch.seed, batch.threads);
            if (reason.empty()) {
                out << "experiment " << e->name << ": kept (finished earlier; --resume)" << std::endl;
                kept.push_back(e->name);
                set_interruption_message(describe_interruption(batch, kept, next));
                continue;
            }
            out << "experiment " << e->name << ": running again (" << reason << ")" << std::endl;
        }
        set_interruption_message(describe_interruption(batch, kept, e->name));

        ExperimentContext ctx;
        ctx.quick = batch.quick;
        ctx.output_dir = staging;
        ctx.assets = batch.assets;
        ctx.seed = batch.seed;
        ctx.threads = batch.threads;
        ctx.log = &out;
        out << "experiment " << e->name << (batch.quick ? " (quick)" : "") << ": " << e->description << std::endl;
        try {
            run_and_write(*e, ctx);
            publish_directory(staging, final_dir);
            kept.push_back(e->name);
            set_interruption_message(describe_interruption(batch, kept, next));
            out << "  wrote " << (final_dir / "table.md").string() << std::endl;
        } catch (const Error& error) {
            fs::remove_all(staging, ec);
            set_interruption_message(describe_interruption(batch, kept, next));
            err << "gilab: experiment " << e->name << " failed: " << error.what() << std::endl;
            ++failures;
        }
    }
    return failures ? 1 : 0;
}

}  // namespace gilab
