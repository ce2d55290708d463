#include "experiments/runner/path_reference.hpp"

#include "core/util/error.hpp"
#include "core/util/produce_once.hpp"
#include "core/util/temporary_path.hpp"
#include "core/image/image_io.hpp"
#include "core/scene/scene_hash.hpp"
#include "core/util/settings.hpp"
#include "techniques/technique.hpp"

namespace gilab {

namespace fs = std::filesystem;

uint64_t reference_seed(uint64_t run_seed) { return run_seed ^ 0x5245464552454eull; }

fs::path reference_store(const ExperimentContext& ctx) { return ctx.output_dir.parent_path() / ".references"; }

namespace {

// The path tracer's settings for the view.
nlohmann::json tracer_settings(const ExperimentContext& ctx, const ReferenceView& view) {
    return {{"spp", view.spp},
            {"seed", view.seed.value_or(reference_seed(ctx.seed))},
            {"max_depth", 8},
            {"jitter", view.jitter}};
}

// The file name: the size and samples to read, and a digest of the scene's content,
// every setting given to the path tracer (the rest are its defaults, which are part of
// its code), the digest of the path tracer's code, and the camera.
std::string reference_name(const ExperimentContext& ctx, const ReferenceView& view) {
    nlohmann::json key = tracer_settings(ctx, view);
    key["scene"] = view.scene->name;
    key["scene_content"] = scene_content_hash(*view.scene);
    key["path_tracer_revision"] = GILAB_PATH_TRACER_REVISION;
    const EyeCamera& camera = view.camera;
    key["width"] = camera.width();
    key["height"] = camera.height();
    const Vec3& p = camera.position();
    const Quat& q = camera.orientation();
    const FrustumTangents& f = camera.fov();
    key["camera"] = {p.x, p.y, p.z, q.w, q.x, q.y, q.z, f.left, f.right, f.bottom, f.top};
    return "reference_path_" + std::to_string(camera.width()) + "px_" + std::to_string(view.spp) + "spp_" +
           Settings(key).hash().substr(0, 12) + ".exr";
}

Film render_reference(const ExperimentContext& ctx, const ReferenceView& view) {
    ctx.say("rendering the path-traced reference (" + std::to_string(view.camera.width()) + "², " +
            std::to_string(view.spp) + " spp) ...");
    auto path = prepare_technique("path", *view.scene, Settings(tracer_settings(ctx, view), "path-traced reference"));
    std::vector<Film> films;
    path->render(ViewSet::mono(view.camera), films);
    ctx.say("reference done in " + std::to_string(path->stats().get("render_ms") / 1000.0) + " s");
    return films.at(0);
}

// The stored image if it is whole and of the view's size, else nothing.
std::optional<Film> read_stored(const ExperimentContext& ctx, const fs::path& file, const ReferenceView& view) {
    try {
        Film film = read_exr(file);
        if (film.width() == view.camera.width() && film.height() == view.camera.height() && film.has_layer("indirect"))
            return film;
        ctx.say("stored reference " + file.string() + " is not of this view; rendering it again");
    } catch (const Error& e) {
        ctx.say(std::string("stored reference unreadable, rendering it again: ") + e.what());
    }
    return std::nullopt;
}

// `from` as ctx.output_dir/name: a hard link where the filesystem allows, else a copy;
// made under a temporary name and renamed, as tasks of one experiment may do it at once.
void place_in_experiment(const ExperimentContext& ctx, const fs::path& from, const std::string& name) {
    const fs::path here = ctx.output_dir / name;
    if (fs::exists(here)) return;
    const fs::path temporary = temporary_sibling(here);
    std::error_code ec;
    fs::create_hard_link(from, temporary, ec);
    try {
        if (ec) fs::copy_file(from, temporary);
        fs::rename(temporary, here);
    } catch (const fs::filesystem_error& e) {
        fs::remove(temporary, ec);
        throw Error(here.string(), std::string("cannot place the reference here: ") + e.what());
    }
}

}  // namespace

Film path_reference(const ExperimentContext& ctx, const ReferenceView& view, std::vector<std::string>& files) {
    if (!view.scene) throw Error("path reference", "no scene given");
    const std::string name = reference_name(ctx, view);
    const fs::path store = reference_store(ctx);
    fs::create_directories(store);
    fs::create_directories(ctx.output_dir);
    const fs::path stored = store / name;
    std::optional<Film> film;
    ProduceOnceOptions options;
    options.say = [&ctx](const std::string& s) { ctx.say(s); };
    for (int attempt = 0; !film; ++attempt) {
        const bool rendered = produce_file_once(stored, [&](const fs::path& temporary) {
            film = render_reference(ctx, view);
            write_exr(temporary, *film);
        }, options);
        if (!rendered) {
            ctx.say("reference from the store " + stored.string());
            film = read_stored(ctx, stored, view);
            if (!film) {
                if (attempt > 0) throw Error(stored.string(), "the stored reference cannot be read after rendering it again");
                fs::remove(stored);
            }
        }
    }
    place_in_experiment(ctx, stored, name);
    const fs::path png = ctx.output_dir / (name.substr(0, name.size() - 4) + ".png");
    if (!fs::exists(png)) write_png(png, *film);
    files.push_back(name);
    return *film;
}

Film path_reference(const ExperimentContext& ctx, const Scene& scene, const EyeCamera& camera, int spp,
                    std::vector<std::string>& files, bool jitter, std::optional<uint64_t> seed) {
    return path_reference(ctx, ReferenceView{&scene, camera, spp, jitter, seed}, files);
}

}  // namespace gilab
