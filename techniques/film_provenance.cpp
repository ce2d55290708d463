#include "techniques/film_provenance.hpp"

#include "core/util/build_info.hpp"
#include "core/util/format.hpp"

namespace gilab {

void write_film_provenance(Film& film, const std::string& technique, const ViewSet& views, size_t view, uint64_t seed,
                           const std::string& config_hash) {
    film.metadata["technique"] = technique;
    film.metadata["view"] = view < views.names.size() ? views.names[view] : "mono";
    film.metadata["seed"] = std::to_string(seed);
    if (!config_hash.empty()) film.metadata["config_hash"] = config_hash;
    film.metadata["git_revision"] = build_git_revision();
}

void write_render_time(std::vector<Film>& films, double render_ms) {
    for (Film& film : films) film.metadata["render_time_seconds"] = format_number(render_ms / 1000.0);
}

}  // namespace gilab
