#include "techniques/lpv/lpv_settings.hpp"

#include <string>
#include "core/util/error.hpp"

namespace gilab {

const SettingsSchema& LpvSettings::schema() {
    static const SettingsSchema schema = [] {
        const LpvSettings d;
        SettingsSchema s("lpv", "cascaded light propagation volumes (Kaplanyan & Dachsbacher 2010)");
        s.integer("cascades", d.cascades).range(1, 8).unit("cascades")
            .doc("Nested grids centred on the viewer, each with cells twice the size of the last.");
        s.integer("resolution", d.resolution).range(4, 128).unit("cells per axis, even")
            .doc("Cells per axis of every cascade (the grid's centre is a cell corner, so it is even).");
        s.number("cell_size", d.cell_size).at_least(0).unit("scene units")
            .doc("Cell of the finest cascade; 0: the coarsest cascade, centred on the scene's camera, reaches the scene's "
                 "farthest corner.");
        s.integer("rsm_size", d.rsm_size).range(1, 2048).unit("texels per side")
            .doc("Reflective shadow map size: per light (point lights: per cube face; emissive triangles: one map "
                 "shared by all, sampled by power). Each texel that hits a surface is one VPL.")
            // The sampling density of the reflected light: more converges towards the
            // one-bounce answer; iterations instead change how far light travels.
            .quality_knob(4, 1024);
        s.integer("iterations", d.iterations).range(1, 256).unit("propagation steps")
            .doc("Propagation iterations per cascade: how many cells light travels.");
        s.boolean("occlusion", d.occlusion)
            .doc("Fuzzy occlusion by the geometry volume (surfels of the RSMs and the primary hits), from the second "
                 "iteration on.");
        s.number("dampening", d.dampening).range(0, 4).unit("cells")
            .doc("Lookup moved this far along the normal, against self-illumination and leaking through walls.");
        s.boolean("gradient_dampening", d.gradient_dampening)
            .doc("Also look up half a cell in front of and behind the surface; where the light reaching it grows "
                 "towards its back it comes through the wall, and is scaled by front / behind (per channel).");
        s.integer("light_samples", d.light_samples).range(1, 1024).doc("Samples per area-light evaluation (direct light).");
        s.integer("seed", int64_t(d.seed)).at_least(0).doc("Seed of every random stream (same seed, same image).");
        s.integer("tile_size", d.tile_size).at_least(1).unit("pixels").doc("Square screen tile of one parallel task.");
        return s;
    }();
    return schema;
}

LpvSettings LpvSettings::from(const Settings& s) {
    const SettingsSchema& schema = LpvSettings::schema();
    LpvSettings v;
    v.cascades = schema.get<int>(s, "cascades");
    v.resolution = schema.get<int>(s, "resolution");
    v.cell_size = schema.get<double>(s, "cell_size");
    v.rsm_size = schema.get<int>(s, "rsm_size");
    v.iterations = schema.get<int>(s, "iterations");
    v.occlusion = schema.get<bool>(s, "occlusion");
    v.dampening = schema.get<float>(s, "dampening");
    v.gradient_dampening = schema.get<bool>(s, "gradient_dampening");
    v.light_samples = schema.get<int>(s, "light_samples");
    v.seed = uint64_t(schema.get<int64_t>(s, "seed"));
    v.tile_size = schema.get<int>(s, "tile_size");
    if (v.resolution % 2 != 0) {
        std::string message = "setting 'resolution' must be even (the grid is centred on a cell corner), got ";
        message += std::to_string(v.resolution);
        throw Error(s.context(), message);
    }
    return v;
}

}  // namespace gilab
