// Shadow DAG over light space (P2 §3): merge rules, SVO ↔ DAG, tiling, double depth
// maps, and lookups against Embree shadow rays.
#include <gtest/gtest.h>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <vector>
#include "accel/dag/dag_layout.hpp"
#include "accel/shadow/light_shadow_dags.hpp"
#include "accel/shadow/shadow_dag.hpp"
#include "accel/shadow/shadow_map.hpp"
#include "core/scene/camera.hpp"
#include "core/util/parallel.hpp"
#include "core/render/ray_tracer.hpp"
#include "core/scene/scene.hpp"
#include "scenes/procedural_meshes.hpp"
#include "scenes/villa_and_terrain.hpp"
#include "tests/test_support.hpp"

using namespace gilab;
using S = ShadowState;

namespace {

// ---- Synthetic depth maps (no ray tracing) ----

struct Maps {
    uint32_t size = 0;
    std::vector<float> d1, d2;
    ShadowState voxel(uint32_t x, uint32_t y, uint32_t z) const {
        const size_t i = size_t(y) * size + x;
        const float c = z + 0.5f;
        if (c < d1[i]) return S::Lit;
        if (c >= d2[i]) return S::Shadow;
        return S::Undefined;
    }
};

// A rolling heightfield of depths with a few thick "closed" blocks whose interiors are
// undefined when `closed` (D2 > D1), plus some empty columns.
Maps make_maps(uint32_t size, bool closed, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    const float a = u(rng) * 6, b = u(rng) * 6;
    Maps m;
    m.size = size;
    m.d1.resize(size_t(size) * size);
    m.d2.resize(m.d1.size());
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            const size_t i = size_t(y) * size + x;
            float d = size * (0.55f + 0.2f * std::sin(x * 0.21f + a) * std::cos(y * 0.17f + b));
            float e = d;
            const bool block = (x / 8 + y / 8) % 3 == 0;
            if (block) {
                d = size * 0.3f + (x % 8);  // a block nearer the light
                e = closed ? d + size * 0.2f : d;
            }
            if (x % 13 == 5 && y % 11 == 3) d = e = kInfinity;  // nothing hit
            m.d1[i] = d;
            m.d2[i] = e;
        }
    return m;
}

ShadowDag dag_from_maps(const Maps& m, int depth, uint32_t tile,
                        ShadowState undefined_as = ShadowDagOptions{}.undefined_as) {
    ShadowDagOptions o;
    o.tile_texels = tile;
    o.undefined_as = undefined_as;
    return ShadowDag::build(depth, [&](uint32_t x0, uint32_t y0, uint32_t size, LightDepthTile& t) {
        std::vector<float> d1(size_t(size) * size, kInfinity), d2 = d1;
        for (uint32_t y = 0; y < size; ++y)
            for (uint32_t x = 0; x < size; ++x)
                if (x0 + x < m.size && y0 + y < m.size) {
                    d1[size_t(y) * size + x] = m.d1[size_t(y0 + y) * m.size + x0 + x];
                    d2[size_t(y) * size + x] = m.d2[size_t(y0 + y) * m.size + x0 + x];
                }
        t.assign(x0, y0, size, std::move(d1), std::move(d2));
    }, o);
}

LightDepthTile whole_tile(const Maps& m) {
    LightDepthTile t;
    t.assign(0, 0, m.size, m.d1, m.d2);
    return t;
}

// The paper's rules applied literally, bottom-up from single voxels.
ShadowState reference_state(const Maps& m, UVec3 first, uint32_t size) {
    if (size == 1) return m.voxel(first.x, first.y, first.z);
    std::array<ShadowState, 8> kids;
    for (int s = 0; s < 8; ++s)
        kids[s] = reference_state(m, first + UVec3(s & 1, (s >> 1) & 1, (s >> 2) & 1) * (size / 2), size / 2);
    return combine_child_states(kids);
}

}  // namespace

TEST(ShadowState, MergeRulesOnHandBuiltCases) {
    auto combine = [](std::array<S, 8> k) { return combine_child_states(k); };
    const S L = S::Lit, D = S::Shadow, U = S::Undefined, B = S::Boundary;
    EXPECT_EQ(combine({L, L, L, L, L, L, L, L}), L);
    EXPECT_EQ(combine({D, D, D, D, D, D, D, D}), D);
    EXPECT_EQ(combine({U, U, U, U, U, U, U, U}), U);
    // Only {lit, undefined} ⇒ lit; only {shadow, undefined} ⇒ shadow.
    EXPECT_EQ(combine({L, U, U, U, U, U, U, U}), L);
    EXPECT_EQ(combine({U, U, L, L, U, L, U, U}), L);
    EXPECT_EQ(combine({U, D, U, U, U, U, U, U}), D);
    EXPECT_EQ(combine({D, D, U, D, U, U, D, U}), D);
    // Lit beside shadow, or any boundary child, must be subdivided.
    EXPECT_EQ(combine({L, D, L, L, L, L, L, L}), B);
    EXPECT_EQ(combine({L, D, U, U, U, U, U, U}), B);
    EXPECT_EQ(combine({L, L, L, L, L, L, L, B}), B);
    EXPECT_EQ(combine({U, U, U, U, B, U, U, U}), B);
    // The 16-bit mask stores 2 bits per child and ranks only boundary children.
    uint32_t mask = 0;
    const std::array<S, 8> states{L, B, D, U, B, L, B, D};
    for (int s = 0; s < 8; ++s) mask = with_child_state(mask, s, states[s]);
    for (int s = 0; s < 8; ++s) EXPECT_EQ(child_state(mask, s), states[s]);
    EXPECT_EQ(boundary_count(mask), 3u);
    EXPECT_EQ(boundary_rank(mask, 4), 1u);
    EXPECT_EQ(boundary_rank(mask, 6), 2u);
}

TEST(ShadowSvo, StatesFollowThePaperRulesBottomUp) {
    for (bool closed : {false, true}) {
        const Maps m = make_maps(32, closed, 7);
        const LightDepthTile tile = whole_tile(m);
        const ShadowSvo svo = ShadowSvo::build(tile, UVec3(0), 0, 5);
        ASSERT_EQ(svo.root_state(), S::Boundary);
        // Walk the SVO breadth-first; every stored child state equals the rule result.
        std::vector<UVec3> cells{UVec3(0)}, next;
        size_t checked = 0;
        for (size_t i = 0; i < svo.interior_levels(); ++i) {
            const uint32_t half = 32u >> (i + 1);
            next.clear();
            for (size_t j = 0; j < cells.size(); ++j) {
                EXPECT_EQ(svo.first_child(i)[j], next.size());
                for (int s = 0; s < 8; ++s) {
                    const UVec3 c = cells[j] + UVec3(s & 1, (s >> 1) & 1, (s >> 2) & 1) * half;
                    const S want = reference_state(m, c, half);
                    // Undefined children of a boundary node are stored as shadow (the default).
                    ASSERT_EQ(child_state(svo.masks(i)[j], s), stored_child_state(want, S::Shadow))
                        << "closed " << closed << " level " << i;
                    ++checked;
                    if (want == S::Boundary) next.push_back(c);
                }
            }
            cells.swap(next);
        }
        ASSERT_EQ(cells.size(), svo.leaves().size());
        for (size_t j = 0; j < cells.size(); ++j)
            for (uint32_t k = 0; k < 64; ++k) {
                const UVec3 v = cells[j] + UVec3(k & 3, (k >> 2) & 3, k >> 4);
                const bool shadow = (svo.leaves()[j] >> k) & 1;
                EXPECT_EQ(shadow, m.voxel(v.x, v.y, v.z) != S::Lit);  // undefined voxels too, by default
            }
        EXPECT_GT(checked, 100u);
    }
}

TEST(ShadowDag, DecodesToExactlyTheSvoItCameFrom) {
    for (bool closed : {false, true}) {
        const Maps m = make_maps(64, closed, 3);
        const ShadowSvo svo = ShadowSvo::build(whole_tile(m), UVec3(0), 0, 6);
        const ShadowDag dag = dag_from_maps(m, 6, 64);
        EXPECT_TRUE(dag.expand() == svo) << "closed " << closed;
        EXPECT_LT(dag.node_count(), svo.node_count());  // something merged
        // Every voxel answers as the depth maps say (undefined voxels may answer either).
        for (uint32_t z = 0; z < 64; ++z)
            for (uint32_t y = 0; y < 64; ++y)
                for (uint32_t x = 0; x < 64; ++x) {
                    const S want = m.voxel(x, y, z);
                    if (want == S::Undefined) continue;
                    ASSERT_EQ(state_is_lit(dag.voxel_state(UVec3(x, y, z))), want == S::Lit) << x << "," << y << "," << z;
                }
    }
}

TEST(ShadowDag, TiledAndUntiledBuildsAreIdentical) {
    for (bool closed : {false, true}) {
        const Maps m = make_maps(60, closed, 11);  // 60 < 64: columns beyond the grid are empty
        const ShadowDag whole = dag_from_maps(m, 6, 64);
        for (uint32_t tile : {4u, 8u, 16u, 32u}) {
            const ShadowDag tiled = dag_from_maps(m, 6, tile);
            EXPECT_EQ(tiled.build_stats().tiles, (64u / tile) * (64u / tile));
            ASSERT_EQ(tiled.words().size(), whole.words().size()) << "tile " << tile;
            EXPECT_TRUE(std::equal(tiled.words().begin(), tiled.words().end(), whole.words().begin()));
            EXPECT_EQ(tiled.level_node_counts(), whole.level_node_counts());
        }
    }
}

TEST(ShadowDag, DoubleDepthAgreesOutsideClosedGeometryAndIsSmaller) {
  for (S undefined_as : {S::Lit, S::Shadow}) {
    const Maps plain = make_maps(64, false, 5);
    const Maps closed = make_maps(64, true, 5);
    const ShadowDag a = dag_from_maps(plain, 6, 16);
    const ShadowDag b = dag_from_maps(closed, 6, 16, undefined_as);
    size_t compared = 0;
    for (uint32_t z = 0; z < 64; ++z)
        for (uint32_t y = 0; y < 64; ++y)
            for (uint32_t x = 0; x < 64; ++x) {
                if (closed.voxel(x, y, z) == S::Undefined) continue;  // inside a closed object
                ASSERT_EQ(state_is_lit(a.voxel_state(UVec3(x, y, z))), state_is_lit(b.voxel_state(UVec3(x, y, z))));
                ++compared;
            }
    EXPECT_GT(compared, 200000u);
    EXPECT_LT(b.bytes(), a.bytes());
  }
}

namespace {

// What the paper's tree holds for a voxel: the state of the first cell on its path that
// the rules do not subdivide (at the 4³ leaves, the voxel's own state). `cells` keeps
// each cell's state (by size and first voxel), so that a whole grid costs one pass of the
// rules per level rather than one per voxel.
using CellStates = std::map<std::array<uint32_t, 4>, ShadowState>;
ShadowState folded_state(const Maps& m, const UVec3& v, uint32_t grid, CellStates& cells) {
    for (uint32_t size = grid; size >= 4; size /= 2) {
        const UVec3 first = v / size * size;
        const std::array<uint32_t, 4> key{size, first.x, first.y, first.z};
        auto cell = cells.find(key);
        if (cell == cells.end()) cell = cells.emplace(key, reference_state(m, first, size)).first;
        if (cell->second != S::Boundary) return cell->second;
    }
    return m.voxel(v.x, v.y, v.z);
}

}  // namespace

// A closed block (undefined inside) beside an open surface at depth 10: the 8³ cells they
// share hold lit, shadow and undefined voxels, so they are subdivided and the block's
// all-undefined 4³ leaves become children of boundary nodes. This is a contact: a
// lookup moved off the open surface by the bias lands inside the block. Undefined space
// the rules leave must answer shadow, as a plain depth map does behind D1; the old
// storage (and today's undefined_as = Lit option) answers lit there.
TEST(ShadowDag, UndefinedSpaceLeftByTheRulesAnswersShadow) {
    Maps m;
    m.size = 32;
    m.d1.assign(32 * 32, kInfinity);
    m.d2 = m.d1;
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 0; x < 32; ++x) {
            const size_t i = size_t(y) * 32 + x;
            if (x < 14) {
                m.d1[i] = 2;   // the closed block, entered at 2 and left at 30
                m.d2[i] = 30;
            } else if (x < 20) {
                m.d1[i] = m.d2[i] = 10;  // an open surface touching it
            }
        }
    const ShadowDag shadow = dag_from_maps(m, 5, 32);
    const ShadowDag lit = dag_from_maps(m, 5, 32, S::Lit);
    EXPECT_EQ(ShadowDagOptions{}.undefined_as, S::Shadow);
    size_t undefined = 0;
    CellStates cells;
    for (uint32_t z = 0; z < 32; ++z)
        for (uint32_t y = 0; y < 32; ++y)
            for (uint32_t x = 0; x < 32; ++x) {
                const UVec3 v(x, y, z);
                const DVec3 centre(x + 0.5, y + 0.5, z + 0.5);
                const S want = folded_state(m, v, 32, cells);
                if (want != S::Undefined) {
                    ASSERT_EQ(shadow.lit_at(centre), want == S::Lit) << x << "," << y << "," << z;
                    continue;
                }
                ++undefined;
                ASSERT_FALSE(shadow.lit_at(centre)) << "undefined voxel answers lit at " << x << "," << y << "," << z;
                ASSERT_TRUE(lit.lit_at(centre)) << x << "," << y << "," << z;
            }
    EXPECT_GT(undefined, 500u);  // the rules leave undefined space next to the contact
}

TEST(DagLayout, CanonicalOrderIgnoresInsertionOrder) {
    // The same two-level DAG inserted in two orders lays out to the same words.
    auto make = [](bool reversed) {
        std::vector<DagLevelTable> t(2);
        const uint32_t leaves[3][2] = {{1, 2}, {3, 4}, {5, 6}};
        std::vector<uint32_t> id(3);
        for (int k = 0; k < 3; ++k) {
            const int i = reversed ? 2 - k : k;
            id[i] = t[1].find_or_insert(0, leaves[i], 2);
        }
        const uint32_t kids[3] = {id[2], id[0], id[2]};
        const uint32_t root = t[0].find_or_insert(0x2a, kids, 3);
        DagLayoutOptions o;
        o.payload_level = 1;
        o.payload_header = false;
        return lay_out_dag(t, std::vector<uint32_t>{root}, o, "test");
    };
    const DagLayout a = make(false), b = make(true);
    EXPECT_EQ(a.words, b.words);
    // Root: header, then addresses of leaf {5,6} (first referenced) and {1,2}; leaf {3,4} is unreachable.
    const std::vector<uint32_t> want = {0x2a, 4, 6, 4, 5, 6, 1, 2};
    EXPECT_EQ(a.words, want);
    EXPECT_EQ(a.level_counts, (std::vector<uint64_t>{1, 2}));
}

// ---- Scenes traced with Embree ----

namespace {

// A box (make_box), or an open one without its top face (y = hi.y).
Mesh box_mesh(const Vec3& lo, const Vec3& hi, bool closed = true) {
    Mesh m = make_box("box", lo, hi, 0);
    if (closed) return m;
    std::erase_if(m.triangles, [&](const UVec3& t) {
        return m.positions[t.x].y == hi.y && m.positions[t.y].y == hi.y && m.positions[t.z].y == hi.y;
    });
    m.material_ids.assign(m.triangles.size(), 0);
    return m;
}

Scene shadow_test_scene(bool closed_boxes, LightType light_type) {
    Scene s;
    s.name = "shadow-test";
    s.source = "builtin:shadow-test";
    s.materials.push_back(Material{});
    Mesh ground;
    ground.positions = {{-4, 0, -4}, {4, 0, -4}, {4, 0, 4}, {-4, 0, 4}};
    ground.triangles = {{0, 2, 1}, {0, 3, 2}};
    ground.material_ids = {0, 0};
    s.add_mesh_instance(ground);
    s.add_mesh_instance(box_mesh({-1.5f, 0.0f, -1}, {-0.5f, 1.5f, 0}, closed_boxes));
    s.add_mesh_instance(box_mesh({0.5f, 0.8f, 0.5f}, {1.6f, 1.2f, 1.4f}, closed_boxes));
    PunctualLight l;
    l.name = "sun";
    l.type = light_type;
    l.direction = glm::normalize(Vec3(-0.8f, -1, -0.6f));  // low sun: long shadows
    if (light_type == LightType::Point) l.position = Vec3(0.2f, 2.0f, 0.6f);  // between the boxes, above
    if (light_type == LightType::Spot) {
        l.position = Vec3(3, 7, 2.5f);
        l.direction = glm::normalize(Vec3(0) - l.position);
        l.cos_outer = std::cos(0.6f);
        l.cos_inner = std::cos(0.5f);
    }
    s.lights.push_back(l);
    return s;
}

struct Surface {
    Vec3 p, n;
};

// Visible points on the scene's surfaces, seen from a camera above (or from the far
// side, where most surfaces seen are turned away from the light).
std::vector<Surface> visible_points(const RayTracer& tracer, int count, const Vec3& eye = Vec3(2, 6, 6)) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Surface> out;
    for (int i = 0; i < count * 4 && int(out.size()) < count; ++i) {
        Ray r;
        r.origin = eye;
        r.direction = glm::normalize(Vec3(u(rng) * 3, 0.5f, u(rng) * 3) - eye);
        const Hit h = tracer.intersect(r);
        if (!h.valid()) continue;
        Vec3 n = glm::normalize(h.geometric_normal);
        if (glm::dot(n, r.direction) > 0) n = -n;
        out.push_back({r.at(h.t), n});
    }
    return out;
}

bool ray_lit(const RayTracer& tracer, const Vec3& p, const Vec3& n, const PunctualLight& light) {
    Ray r;
    r.origin = p + n * 1e-4f;
    if (light.type == LightType::Directional) {
        r.direction = -glm::normalize(light.direction);
    } else {
        r.direction = light.position - r.origin;
        r.tmax = 1.0f - 1e-4f;
    }
    return !tracer.occluded(r);
}

// Whether the ray-traced answer changes within one voxel of where the structures look p
// up (the biased lookup point), along the grid's three axes and diagonals: a mismatch
// there is the voxel quantization, anywhere else an error.
bool within_one_voxel_of_a_boundary(const RayTracer& tracer, const LightSpace& space, const Surface& s,
                                    const PunctualLight& light) {
    const bool here = ray_lit(tracer, s.p, s.n, light);
    const Vec3 to_light = space.to_light_direction(s.p);
    const Vec3 n = glm::dot(s.n, to_light) < 0 ? -s.n : s.n;
    const float v = space.voxel_world_size(s.p);
    const Vec3 q = s.p + n * (1.5f * v) + to_light * v;  // the lookup point
    for (int k = 0; k < 27; ++k) {
        const Vec3 d = float(k % 3 - 1) * space.axis_x() + float(k / 3 % 3 - 1) * space.axis_y() +
                       float(k / 9 - 1) * space.axis_z();
        for (float f : {0.5f, 1.0f}) {
            const Vec3 o = q + d * (v * f);
            Ray r;
            r.origin = o;
            if (light.type == LightType::Directional) {
                r.direction = -glm::normalize(light.direction);
            } else {
                r.direction = light.position - o;
                r.tmax = 1.0f - 1e-4f;
            }
            if (!tracer.occluded(r) != here) return true;
        }
    }
    return false;
}

// Whether the ray-traced answer changes within `radius` of p along the surface.
bool near_boundary(const RayTracer& tracer, const Surface& s, const PunctualLight& light, float radius) {
    const bool here = ray_lit(tracer, s.p, s.n, light);
    const Vec3 t1 = glm::normalize(glm::cross(s.n, std::abs(s.n.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
    const Vec3 t2 = glm::cross(s.n, t1);
    for (int i = 0; i < 16; ++i) {
        const float a = i * 2 * kPi / 16;
        for (float f : {0.5f, 1.0f}) {
            const Vec3 q = s.p + (t1 * std::cos(a) + t2 * std::sin(a)) * radius * f;
            if (ray_lit(tracer, q, s.n, light) != here) return true;
        }
    }
    return false;
}

void expect_matches_rays(LightType type, bool closed_boxes, bool double_depth) {
    const Scene scene = shadow_test_scene(closed_boxes, type);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const PunctualLight& light = frame.lights[0];
    ShadowDagOptions o;
    o.resolution = 256;
    o.double_depth = double_depth;
    const ShadowDag dag = ShadowDag::build(scene, tracer, light, o);
    const ShadowMap map = ShadowMap::build(tracer, light, 256, 32);
    std::vector<Surface> pts = visible_points(tracer, 4000);
    ASSERT_GT(pts.size(), 3000u);
    const std::vector<Surface> far_side = visible_points(tracer, 1000, Vec3(-4, 3, -5));
    pts.insert(pts.end(), far_side.begin(), far_side.end());
    int mismatches = 0, map_mismatches = 0, shadowed = 0, turned_away = 0;
    for (const Surface& s : pts) {
        const bool truth = ray_lit(tracer, s.p, s.n, light);
        shadowed += !truth;
        turned_away += !dag.space()->faces_light(s.p, s.n);
        const bool d = dag.visibility(s.p, s.n) > 0.5f;
        const bool m = map.visibility(s.p, s.n) > 0.5f;
        if (d != truth) {
            ++mismatches;
            EXPECT_TRUE(within_one_voxel_of_a_boundary(tracer, *dag.space(), s, light))
                << "DAG mismatch more than a voxel from any shadow boundary at " << s.p.x << "," << s.p.y << ","
                << s.p.z;
        }
        if (m != truth) ++map_mismatches;
    }
    EXPECT_GT(shadowed, 100);     // the test sees shadows at all
    EXPECT_GT(turned_away, 100);  // and surfaces turned away from the light
    EXPECT_LT(mismatches, int(pts.size()) / 50) << "mismatches are rare";
    EXPECT_LT(map_mismatches, int(pts.size()) / 50);
}

}  // namespace

namespace {

// Random points on the frame's surfaces, by area, whose normal faces the light with
// n·L > 0.2 (as the Python check does).
std::vector<Surface> surface_points_facing(const SceneFrame& frame, const Vec3& to_light, size_t count) {
    std::vector<std::pair<const WorldMesh*, UVec3>> triangles;
    std::vector<double> areas;
    for (const WorldMesh& m : frame.meshes)
        for (const UVec3& t : m.triangles) {
            triangles.push_back({&m, t});
            areas.push_back(glm::length(glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x])));
        }
    std::mt19937 rng(1);
    std::discrete_distribution<size_t> pick(areas.begin(), areas.end());
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Surface> out;
    for (size_t tries = 0; out.size() < count && tries < 100 * count; ++tries) {
        const auto& [mesh, t] = triangles[pick(rng)];
        const Vec3 a = mesh->positions[t.x], b = mesh->positions[t.y], c = mesh->positions[t.z];
        float s = u(rng), r = u(rng);
        if (s + r > 1) s = 1 - s, r = 1 - r;
        const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
        if (glm::dot(n, to_light) > 0.2f) out.push_back({a + s * (b - a) + r * (c - a), n});
    }
    return out;
}

double share_agreeing_with_rays(const ShadowDag& dag, const RayTracer& tracer, const std::vector<Surface>& pts,
                                const PunctualLight& light) {
    size_t agree = 0;
    for (const Surface& s : pts) agree += (dag.visibility(s.p, s.n) > 0.5f) == ray_lit(tracer, s.p, s.n, light);
    return double(agree) / double(pts.size());
}

}  // namespace

// The villa's closed parts touch and cross everywhere (walls sunk into the ground slab,
// roofs on walls): lookups of those surfaces land inside the next part, in undefined
// space that the merge rules fold into lit next to the part's lit side. With undefined
// space ended a band before such surfaces and stored as shadow, S3 agrees with shadow
// rays as well as S2 up to one point in a thousand (the Python check's kind of points:
// random by area, facing the sun). Before, S3 agreed on 95.3 % against S2's 98.9 %.
TEST(ShadowDag, DoubleDepthAgreesWithShadowRaysAsWellAsThePlainDag) {
    const Scene villa = make_villa();
    const SceneFrame frame = villa.evaluate(0);
    const RayTracer tracer(frame);
    const PunctualLight& sun = frame.lights.at(0);
    ASSERT_EQ(sun.type, LightType::Directional);
    const std::vector<Surface> pts = surface_points_facing(frame, -glm::normalize(sun.direction), 2000);
    ASSERT_EQ(pts.size(), 2000u);
    ShadowDagOptions o;
    o.resolution = 1024;
    const double s2 = share_agreeing_with_rays(ShadowDag::build(villa, tracer, sun, o), tracer, pts, sun);
    o.double_depth = true;
    const ShadowDag s3dag = ShadowDag::build(villa, tracer, sun, o);
    const double s3 = share_agreeing_with_rays(s3dag, tracer, pts, sun);
    o.undefined_as = S::Lit;
    const double s3_lit = share_agreeing_with_rays(ShadowDag::build(villa, tracer, sun, o), tracer, pts, sun);
    std::printf("agreement with shadow rays: S2 %.4f, S3 %.4f, S3 undefined as lit %.4f\n", s2, s3, s3_lit);
    EXPECT_GE(s2, 0.97);
    EXPECT_GE(s3, 0.985);
    // One point short of S2 remains: a wall face below ground whose lookup moves sideways
    // into a column of the ground slab that does not meet the wall.
    EXPECT_GE(s3, s2 - 0.001);
    EXPECT_GT(s3, s3_lit);  // stored as lit, the folded interiors leak
}

TEST(ShadowDag, DirectionalLightMatchesShadowRaysUpToOneVoxelOfABoundary) {
    expect_matches_rays(LightType::Directional, true, false);
    expect_matches_rays(LightType::Directional, true, true);
}

// A point light low between the boxes casts shadows in several directions: the cube of six
// spot-frustum DAGs answers like shadow rays, seams included, except within a voxel of a
// shadow boundary; faces that see nothing hold no DAG.
TEST(ShadowDag, PointLightCubeMatchesShadowRaysUpToOneVoxelOfABoundary) {
    const Scene scene = shadow_test_scene(true, LightType::Point);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const PunctualLight& light = frame.lights[0];
    ShadowDagOptions o;
    o.resolution = 256;
    const LightShadowDags dags = LightShadowDags::build(scene, tracer, light, o);
    ASSERT_TRUE(dags.cube());
    EXPECT_FALSE(dags.dag(2).has_value()) << "nothing lies above the light (+y)";
    EXPECT_TRUE(dags.dag(3).has_value());
    EXPECT_EQ(dags.dag_count(), 5u);
    std::vector<Surface> pts = visible_points(tracer, 4000);
    ASSERT_GT(pts.size(), 3000u);
    int mismatches = 0, shadowed = 0;
    LightShadowDags::Cursor cursor;
    for (const Surface& s : pts) {
        const bool truth = ray_lit(tracer, s.p, s.n, light);
        shadowed += !truth;
        if ((dags.visibility(s.p, s.n, 1, cursor) > 0.5f) != truth) {
            ++mismatches;
            const Vec3 r = glm::abs(s.p - light.position);
            const int axis = r.x >= r.y && r.x >= r.z ? 0 : (r.y >= r.z ? 1 : 2);
            const int face = 2 * axis + ((s.p - light.position)[axis] < 0 ? 1 : 0);
            ASSERT_TRUE(dags.dag(face).has_value());
            EXPECT_TRUE(within_one_voxel_of_a_boundary(tracer, *dags.dag(face)->space(), s,
                                                       LightShadowDags::cube_face(light, face)))
                << "mismatch more than a voxel from any shadow boundary at " << s.p.x << "," << s.p.y << "," << s.p.z;
        }
    }
    EXPECT_GT(shadowed, 100);
    EXPECT_LT(mismatches, int(pts.size()) / 50);
    const PunctualLight face = LightShadowDags::cube_face(light, 5);
    EXPECT_EQ(face.type, LightType::Spot);
    EXPECT_EQ(face.direction, Vec3(0, 0, -1));
    EXPECT_EQ(face.position, light.position);
}

// Which cube faces of a point light hold a DAG is decided per triangle, not by rays
// through texel centres: a triangle far smaller than the gap between the 512² rays of
// the +x face, placed between four of them, still gives that face its DAG (thin geometry
// such as fire particles would otherwise lose its shadow without a word).
TEST(ShadowDag, PointLightFaceHoldingOnlyATinyTriangleGetsItsDag) {
    PunctualLight light;
    light.name = "point";
    light.type = LightType::Point;
    light.position = Vec3(0);
    const PunctualLight face = LightShadowDags::cube_face(light, 0);  // +x
    // The directions of four neighbouring rays of a 512² look at the +x face; the
    // triangle sits where they meet, at axial distance 1, a tenth of their spacing wide.
    const Bounds3 unit{Vec3(-1), Vec3(1)};
    const LightSpace probe(face, unit, 512);
    Vec3 mid(0);
    for (uint32_t k = 0; k < 4; ++k) {
        const Vec3 d = probe.texel_ray(255 + (k & 1), 255 + (k >> 1)).direction;
        mid += d / glm::dot(d, face.direction) / 4.0f;
    }
    const float spacing = 2 * std::tan(LightShadowDags::kCubeFaceHalfAngleDegrees * kPi / 180.0f) / 512;
    const float h = 0.05f * spacing;
    Scene scene;
    scene.name = "tiny-triangle";
    scene.source = "builtin:tiny-triangle";
    scene.materials.push_back(Material{});
    Mesh tiny;
    tiny.positions = {mid + Vec3(0, -h, -h), mid + Vec3(0, h, -h), mid + Vec3(0, 0, h)};
    tiny.triangles = {{0, 1, 2}};
    tiny.material_ids = {0};
    scene.add_mesh_instance(tiny);
    Mesh ground;  // below the light, in the −y face only
    ground.positions = {{-0.5f, -1, -0.5f}, {0.5f, -1, -0.5f}, {0.5f, -1, 0.5f}, {-0.5f, -1, 0.5f}};
    ground.triangles = {{0, 2, 1}, {0, 3, 2}};
    ground.material_ids = {0, 0};
    scene.add_mesh_instance(ground);
    scene.lights.push_back(light);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    // No ray of the look hits it: the triangle is found by the triangle test alone.
    for (uint32_t y = 250; y < 262; ++y)
        for (uint32_t x = 250; x < 262; ++x) {
            Ray r = probe.texel_ray(x, y);
            r.origin = light.position;
            ASSERT_FALSE(tracer.intersect(r).valid()) << x << "," << y;
        }
    ShadowDagOptions o;
    o.resolution = 64;
    const LightShadowDags dags = LightShadowDags::build(scene, tracer, light, o);
    EXPECT_TRUE(dags.dag(0).has_value()) << "the +x face holds the tiny triangle";
    EXPECT_TRUE(dags.dag(3).has_value()) << "the −y face holds the ground";
    EXPECT_EQ(dags.dag_count(), 2u);
    // A triangle wholly outside a face's frustum (behind it, or past one side) is not counted.
    const LightSpace plus_x(face, unit, 64);
    EXPECT_TRUE(plus_x.may_overlap_triangle(tiny.positions[0], tiny.positions[1], tiny.positions[2]));
    EXPECT_FALSE(plus_x.may_overlap_triangle(Vec3(-1, 0, 0), Vec3(-1, 0.1f, 0), Vec3(-1, 0, 0.1f)));
    EXPECT_FALSE(plus_x.may_overlap_triangle(Vec3(1, 2, 0), Vec3(1, 2.1f, 0), Vec3(1, 2, 0.1f)));
}

TEST(ShadowDag, SpotLightMatchesShadowRaysUpToOneVoxelOfABoundary) {
    expect_matches_rays(LightType::Spot, true, false);
    expect_matches_rays(LightType::Spot, true, true);
}

TEST(ShadowDag, ClosedMeshesShrinkTheDoubleDepthDag) {
    const Scene scene = shadow_test_scene(true, LightType::Directional);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 256;
    const ShadowDag plain = ShadowDag::build(scene, tracer, frame.lights[0], o);
    o.double_depth = true;
    const ShadowDag folded = ShadowDag::build(scene, tracer, frame.lights[0], o);
    EXPECT_LT(folded.bytes(), plain.bytes());
    EXPECT_GT(folded.build_stats().rays, plain.build_stats().rays);  // exit rays were cast
}

TEST(ShadowDag, WithoutClosedMeshesDoubleDepthChangesNothing) {
    const Scene scene = shadow_test_scene(false, LightType::Directional);  // open boxes
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 128;
    const ShadowDag plain = ShadowDag::build(scene, tracer, frame.lights[0], o);
    o.double_depth = true;
    const ShadowDag folded = ShadowDag::build(scene, tracer, frame.lights[0], o);
    ASSERT_EQ(plain.words().size(), folded.words().size());
    EXPECT_TRUE(std::equal(plain.words().begin(), plain.words().end(), folded.words().begin()));
}

TEST(ShadowDag, SceneBuildsAreTheSameTiledAndUntiled) {
    const Scene scene = shadow_test_scene(true, LightType::Directional);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 200;  // not a power of two
    o.double_depth = true;
    o.tile_texels = 256;
    const ShadowDag whole = ShadowDag::build(scene, tracer, frame.lights[0], o);
    o.tile_texels = 32;
    const ShadowDag tiled = ShadowDag::build(scene, tracer, frame.lights[0], o);
    EXPECT_EQ(tiled.build_stats().tiles, 64u);
    ASSERT_EQ(whole.words().size(), tiled.words().size());
    EXPECT_TRUE(std::equal(whole.words().begin(), whole.words().end(), tiled.words().begin()));
}

TEST(ShadowDag, PercentageCloserFilterSoftensOnlyNearBoundaries) {
    const Scene scene = shadow_test_scene(true, LightType::Directional);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 256;
    const ShadowDag dag = ShadowDag::build(scene, tracer, frame.lights[0], o);
    int partial = 0, changed_far = 0;
    for (const Surface& s : visible_points(tracer, 2000)) {
        const float hard = dag.visibility(s.p, s.n), soft = dag.visibility(s.p, s.n, 3);
        EXPECT_GE(soft, 0.0f);
        EXPECT_LE(soft, 1.0f);
        partial += soft > 0.0f && soft < 1.0f;
        if (std::abs(soft - hard) > 0.5f && !near_boundary(tracer, s, frame.lights[0], 4 * dag.space()->voxel_world_size(s.p)))
            ++changed_far;
    }
    EXPECT_GT(partial, 0);
    EXPECT_EQ(changed_far, 0);
}

TEST(ShadowDag, BadInputIsAClearError) {
    const Scene scene = shadow_test_scene(true, LightType::Directional);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 0;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, frame.lights[0], o); }).find("resolution 0"),
              std::string::npos);
    o.resolution = 1u << 20;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, frame.lights[0], o); }).find("outside 8.."),
              std::string::npos);
    o.resolution = 64;
    o.tile_texels = 24;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, frame.lights[0], o); }).find("power of two"),
              std::string::npos);
    o.tile_texels = 8;  // 1024³ in 8² tiles would be 8^7 cells
    o.resolution = 1024;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, frame.lights[0], o); }).find("too small"),
              std::string::npos);
    o.tile_texels = 0;
    o.memory_limit_bytes = 1000;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, frame.lights[0], o); }).find("memory limit"),
              std::string::npos);
    o.memory_limit_bytes = 0;
    o.resolution = 64;
    PunctualLight point = frame.lights[0];
    point.type = LightType::Point;
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, point, o); }).find("point lights are not supported"),
              std::string::npos);
    PunctualLight away = frame.lights[0];
    away.type = LightType::Spot;
    away.position = Vec3(0, 10, 0);
    away.direction = Vec3(0, 1, 0);  // looks up, away from everything
    away.cos_outer = std::cos(0.3f);
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, away, o); }).find("behind the spot light"),
              std::string::npos);
    away.position = Vec3(0, 3, 0);
    away.direction = glm::normalize(Vec3(1, 0.05f, 0));  // sees the scene box but no geometry
    away.cos_outer = std::cos(0.02f);
    EXPECT_NE(test::error_of([&] { ShadowDag::build(scene, tracer, away, o); }).find("sees no geometry"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] { ShadowMap::build(tracer, frame.lights[0], 100000, 32, 1000000); }).find("memory limit"),
              std::string::npos);
}

TEST(ShadowDag, CursorLookupsAnswerAsFreshOnes) {
    const Maps m = make_maps(64, true, 9);
    const ShadowDag dag = dag_from_maps(m, 6, 64);
    ShadowDag::Cursor scan, jump;
    std::mt19937 rng(4);
    std::uniform_int_distribution<uint32_t> u(0, 63);
    for (uint32_t z = 0; z < 64; ++z)
        for (uint32_t y = 0; y < 64; ++y)
            for (uint32_t x = 0; x < 64; ++x) {
                const UVec3 v(x, y, z), r(u(rng), u(rng), u(rng));
                ASSERT_EQ(dag.voxel_state(v, scan), dag.voxel_state(v));
                ASSERT_EQ(dag.voxel_state(r, jump), dag.voxel_state(r));
            }
}

TEST(LightSpace, TexelRaysHitWhereToLightSaysTheyAre) {
    for (LightType type : {LightType::Directional, LightType::Spot}) {
        const Scene scene = shadow_test_scene(true, type);
        const SceneFrame frame = scene.evaluate(0);
        const LightSpace space(frame.lights[0], frame.bounds, 300);
        for (uint32_t y = 3; y < 300; y += 37)
            for (uint32_t x = 5; x < 300; x += 41)
                for (float t : {0.0f, 17.25f, 151.5f, 299.0f}) {
                    const Ray r = space.texel_ray(x, y);
                    const DVec3 c = space.to_light(r.at(t));
                    EXPECT_NEAR(c.x, x + 0.5, 2e-3) << int(type);
                    EXPECT_NEAR(c.y, y + 0.5, 2e-3) << int(type);
                    EXPECT_NEAR(c.z, t, 2e-3 * std::max(1.0f, t)) << int(type);
                }
    }
}

TEST(ShadowMap, SixteenBitDepthsAreNeverInFrontAndAgreeWithFloats) {
    const Scene scene = shadow_test_scene(true, LightType::Directional);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    const ShadowMap m32 = ShadowMap::build(tracer, frame.lights[0], 200, 32);
    const ShadowMap m16 = ShadowMap::build(tracer, frame.lights[0], 200, 16);
    EXPECT_EQ(m16.bytes(), 200u * 200u * 2u);
    EXPECT_EQ(m32.bytes(), 200u * 200u * 4u);
    size_t hits = 0;
    for (uint32_t y = 0; y < 200; ++y)
        for (uint32_t x = 0; x < 200; ++x) {
            const float a = m32.depth(x, y), b = m16.depth(x, y);
            if (a == kInfinity) {
                EXPECT_EQ(b, kInfinity);
                continue;
            }
            ++hits;
            EXPECT_GE(b, a);                          // rounded up, never in front
            EXPECT_LE(b - a, 200.0f / 65535 + 1e-3f);  // by less than one 16-bit step
        }
    EXPECT_GT(hits, 10000u);
    int differ = 0;
    const auto pts = visible_points(tracer, 2000);
    for (const Surface& s : pts) differ += (m16.visibility(s.p, s.n) > 0.5f) != (m32.visibility(s.p, s.n) > 0.5f);
    EXPECT_LT(differ, 10);
}

TEST(ShadowDag, BuildIsTheSameAtOneAndTwoThreads) {
    const Scene scene = shadow_test_scene(true, LightType::Spot);
    const SceneFrame frame = scene.evaluate(0);
    const RayTracer tracer(frame);
    ShadowDagOptions o;
    o.resolution = 300;
    o.double_depth = true;
    o.tile_texels = 128;
    std::vector<uint32_t> one, two;
    {
        ThreadLimit limit(1);
        const ShadowDag d = ShadowDag::build(scene, tracer, frame.lights[0], o);
        one.assign(d.words().begin(), d.words().end());
    }
    {
        ThreadLimit limit(2);
        const ShadowDag d = ShadowDag::build(scene, tracer, frame.lights[0], o);
        two.assign(d.words().begin(), d.words().end());
    }
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, two);
}
