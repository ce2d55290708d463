#pragma once
// The provenance every technique writes into the films it renders; each technique adds
// the keys of its own settings beside it.
#include <cstdint>
#include <string>
#include <vector>
#include "core/image/film.hpp"
#include "techniques/technique.hpp"

namespace gilab {

// Into the film of view `view`: technique, view (its name in `views`, "mono" when it has
// none), seed, git_revision and, unless `config_hash` is empty, config_hash.
void write_film_provenance(Film& film, const std::string& technique, const ViewSet& views, size_t view, uint64_t seed,
                           const std::string& config_hash = "");

// Into every film of one render() call: render_time_seconds, the call's wall time.
void write_render_time(std::vector<Film>& films, double render_ms);

}  // namespace gilab
