#pragma once
// The interface every global-illumination technique implements, and the registry the
// CLI and the experiments use to look techniques up by name (never by type).
#include <functional>
#include <memory>
#include <string>
#include <vector>
#include "core/scene/camera.hpp"
#include "core/image/film.hpp"
#include "core/scene/scene.hpp"
#include "core/util/settings.hpp"
#include "core/util/settings_schema.hpp"
#include "core/util/stats.hpp"

namespace gilab {

// The views rendered together: one (mono) or two (stereo: left, right).
struct ViewSet {
    std::vector<EyeCamera> views;
    std::vector<std::string> names;  // "mono" or "left", "right"
    bool stereo() const { return views.size() == 2; }
    static ViewSet mono(const EyeCamera& camera) { return {{camera}, {"mono"}}; }
    static ViewSet stereo_pair(const EyeCamera& left, const EyeCamera& right) {
        return {{left, right}, {"left", "right"}};
    }
};

class Technique {
public:
    virtual ~Technique() = default;
    virtual std::string name() const = 0;
    // Reads the technique's settings (every key it understands; the caller reports the
    // rest as errors) and builds what it needs for the scene at time 0.
    virtual void prepare(const Scene& scene, const Settings& settings) = 0;
    // Moves a dynamic scene to time t (seconds). Static scenes may ignore it.
    virtual void update(double time) = 0;
    // Renders every view into films[i] (resized by the technique to the view's size).
    virtual void render(const ViewSet& views, std::vector<Film>& films) = 0;
    // Figures from the last prepare/update/render (timings in ms, counters, bytes).
    virtual Stats stats() const = 0;
};

struct TechniqueInfo {
    std::string name;
    std::string description;
    std::function<std::unique_ptr<Technique>()> create;
    // Every setting the technique reads: key, type, default, range, description and the
    // quality knob of equal-time comparisons (`gilab list settings NAME` prints it).
    std::function<const SettingsSchema&()> settings_schema;
};

class TechniqueRegistry {
public:
    void add(TechniqueInfo info);
    // Throws Error naming the unknown technique and listing the known ones.
    std::unique_ptr<Technique> create(const std::string& name) const;
    const TechniqueInfo* find(const std::string& name) const;
    const std::vector<TechniqueInfo>& list() const { return techniques_; }

    // All built-in techniques, registered explicitly in techniques/registry.cpp.
    static const TechniqueRegistry& builtin();

private:
    std::vector<TechniqueInfo> techniques_;
};

// The set-up every caller of a technique repeats. prepare_technique creates the built-in
// technique `name` (an unknown name is an Error listing the known ones), prepares it for
// `scene` with `settings` after checking every key against the technique's settings
// schema, then reports the settings it never read; the second form
// prepares a technique already made. Errors name the settings' context (the caller)
// and, for unread keys, the technique.
std::unique_ptr<Technique> prepare_technique(const std::string& name, const Scene& scene, const Settings& settings);
void prepare_technique(Technique& technique, const Scene& scene, const Settings& settings);
// Throws Error naming every key of `settings` that the technique's schema does not
// declare, with the nearest declared key: before a prepare that may take minutes.
void check_settings_known(const Technique& technique, const Settings& settings);
// Throws Error naming every key of `settings` that `technique` did not read (misspelt,
// or not one of its settings); for callers with checks of their own between the two.
void report_unused_settings(const Technique& technique, const Settings& settings);

}  // namespace gilab
