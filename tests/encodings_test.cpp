// The compact encodings: dense meets its error targets with no false hits or misses, at the
// sizes documented; candidates is exact (its images equal exact mode's).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <vector>

#include "geometry/chain.h"
#include "geometry/lattice_source.h"
#include "io/image_compare.h"
#include "lattice/encodings/candidates/candidates_table.h"
#include "lattice/cache/table_cache.h"
#include "lattice/certify.h"
#include "lattice/encodings/dense/dense_table.h"
#include "lattice/encoding.h"
#include "lattice/lattice_shape.h"
#include "lattice/rasterizer.h"
#include "render/modes/integrators.h"
#include "render/modes/scene_lattices.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "test_paths.h"
#include "util/error.h"

namespace lat {
namespace {

const Scene& hair_scene() {
    static const Scene s = load_scene(test::source_path("examples/plate3-hair-closeup.json"));
    return s;
}

struct Built {
    ByteBuffer payload;
    std::unique_ptr<LatticeTable> table;
    TableContext ctx;
    RasterizeResult raster;
};

// A table of the scene's first primitive (or of `shape` in its place), its lattice refined k
// times.
Built build_for(const Scene& s, const std::string& encoding, int k, const EncodeOptions& opt = {},
                const Shape* shape = nullptr) {
    const Primitive& p = s.primitives.at(0);
    const LatticeSpec& l = *p.lattice;
    Built b;
    b.ctx = {{l.cells[0] * k, l.cells[1] * k, l.cells[2] * k}, l.sigma / k, l.sigma,
             shape ? shape : p.shape.get()};
    b.raster = rasterize(b.ctx);
    const Encoding& e = find_encoding(encoding);
    b.payload = e.build(b.raster.raw, b.ctx, opt);
    b.table = e.open(b.payload.data(), b.payload.size(), b.raster.hits, b.ctx);
    return b;
}

Built build(const std::string& encoding, int k, const EncodeOptions& opt = {}) {
    return build_for(hair_scene(), encoding, k, opt);
}

// A ray from 30 units away through a random point of the box [0, size].
Ray ray_into(const Vec3& size, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const Vec3 target{size.x * u(rng), size.y * u(rng), size.z * u(rng)};
    const Vec3 d = normalize(Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
    return {target - d * 30, d};
}

std::uint32_t normal_mode(const Built& b) {
    return static_cast<const DenseTable&>(*b.table).layout().normal_mode;  // 1: part codes
}

TEST(EncodingDense, CertifiedWithinTargetsOnTheHair) {
    for (int k : {1, 2}) {
        const Built b = build("dense", k);
        const CertifyReport r = certify_table(*b.table, b.ctx, false);
        EXPECT_EQ(r.false_hits, 0u) << k;
        EXPECT_EQ(r.false_misses, 0u) << k;
        EXPECT_LE(r.max_point_error, 0.01) << k;
        EXPECT_LE(r.max_normal_error_deg, 1.0) << k;
        const double per_hit = double(b.payload.size()) / double(b.raster.hits);
        EXPECT_LT(per_hit, 3.0) << k;  // measured 2.39 and 2.38 (payload only)
    }
}

TEST(EncodingDense, OctahedralNormalsAndLooserTargets) {
    EncodeOptions oct;
    oct.normals = DenseNormals::kOct;
    const Built a = build("dense", 1, oct);
    const CertifyReport ra = certify_table(*a.table, a.ctx, false);
    EXPECT_LE(ra.max_point_error, 0.01);
    EXPECT_LE(ra.max_normal_error_deg, 1.0);
    EXPECT_EQ(normal_mode(a), 0u);
    EncodeOptions loose;
    loose.max_point_error = 0.05;
    loose.max_normal_error_deg = 5;
    const Built b = build("dense", 1, loose);
    const CertifyReport rb = certify_table(*b.table, b.ctx, false);
    EXPECT_LE(rb.max_point_error, 0.05);
    EXPECT_LE(rb.max_normal_error_deg, 5.0);
    EXPECT_EQ(rb.false_hits + rb.false_misses, 0u);
    EXPECT_LT(b.payload.size(), a.payload.size());
}

TEST(EncodingDense, AutoNormalsArePartCodesOnlyWhereTheyAreCheap) {
    // The hair's spheres and cylinders: part codes, the smaller. A torus minus a sphere: its
    // torus's normal is a quartic's gradient, so `auto` stores octahedral codes, within the
    // same targets; `part` still gives part codes when asked.
    EXPECT_EQ(normal_mode(build("dense", 1)), 1u);
    const Scene rings = load_scene(test::source_path("examples/lattice-rings.json"));
    const Built a = build_for(rings, "dense", 1);
    EXPECT_EQ(normal_mode(a), 0u);
    const CertifyReport r = certify_table(*a.table, a.ctx, false);
    EXPECT_EQ(r.false_hits + r.false_misses, 0u);
    EXPECT_LE(r.max_point_error, 0.01);
    EXPECT_LE(r.max_normal_error_deg, 1.0);
    EncodeOptions part;
    part.normals = DenseNormals::kPart;
    EXPECT_EQ(normal_mode(build_for(rings, "dense", 1, part)), 1u);
}

TEST(EncodingDense, BothDirectionsFromOneRecord) {
    const Built b = build("dense", 1);
    for (const RawHit& h : b.raster.raw.flatten()) {
        TableHit fwd, rev;
        ASSERT_TRUE(b.table->lookup(h.a, h.b, fwd));
        ASSERT_TRUE(b.table->lookup(h.b, h.a, rev));
        EXPECT_LE(fwd.t, 1.0 - rev.t + 1e-3);  // the near hit comes before the far one
    }
}

TEST(EncodingDense, RejectsCorruptPayloads) {
    Built b = build("dense", 1);
    const auto& ctx = b.ctx;
    EXPECT_THROW(DenseTable(b.payload.data(), 40, 0, ctx), std::runtime_error);
    EXPECT_THROW(DenseTable(b.payload.data(), b.payload.size() - 8, 0, ctx), std::runtime_error);
    b.payload.data()[8] ^= 1;  // the point count
    EXPECT_THROW(DenseTable(b.payload.data(), b.payload.size(), 0, ctx), std::runtime_error);
}

TEST(EncodingCandidates, ExactOnEveryPair) {
    const Built b = build("candidates", 2);
    const CertifyReport r = certify_table(*b.table, b.ctx, false);
    EXPECT_EQ(r.false_hits, 0u);
    EXPECT_EQ(r.false_misses, 0u);
    EXPECT_LT(r.max_point_error, 1e-5);
    EXPECT_LT(double(b.payload.size()) / double(b.raster.hits), 2.0);
}

TEST(EncodingCandidates, EveryPartARayMeetsIsACandidate) {
    // Random rays through the hair's lattice: every part the real ray hits inside the box is in
    // the candidate list of the pair it snaps to, so lattice answers equal exact ones.
    const Built b = build("candidates", 1);
    const Primitive& p = hair_scene().primitives.at(0);
    const auto shared = std::shared_ptr<const LatticeTable>(b.table.get(), [](const LatticeTable*) {});
    const auto ls = make_lattice_shape(shared, b.ctx, 0.0);
    std::mt19937 rng(17);
    int hits = 0;
    for (int n = 0; n < 50000; ++n) {
        const Ray ray = ray_into({7, 7, 20}, rng);
        Crossing ce, cl;
        const bool exact = p.shape->intersect(ray, 0, kInfinity, ce);
        const bool lattice = ls->intersect(ray, 0, kInfinity, cl);
        ASSERT_EQ(exact, lattice) << n;
        if (exact) {
            ++hits;
            ASSERT_EQ(ce.t, cl.t) << n;
        }
        EXPECT_EQ(p.shape->occluded(ray, 0, kInfinity), ls->occluded(ray, 0, kInfinity)) << n;
    }
    EXPECT_GT(hits, 3000);
}

// The costly-primitive check class: tilted tori minus a sphere, centred in an 8^3 box, placed by `objects`.
Scene tori_scene_with(const std::string& objects) {
    std::string text = R"({
      "camera": {"eye": [15, -12, 9], "look_at": [5, 3, 0], "fov_y_deg": 45, "width": 96, "height": 96},
      "lights": [{"position": [40, -30, 50], "intensity": 0.9}],
      "materials": {"m": {"color": [0.8, 0.6, 0.3], "ks": 0.4}, "cut": {"color": [0.2, 0.4, 0.9]}},
      "primitives": {"tori": {"object": {"type": "csg", "op": "difference", "children": [
          {"type": "csg", "op": "union", "children": [
            {"type": "torus", "center": [4, 4, 4], "axis": [0.06, 0.8, -0.6], "major_radius": 3, "minor_radius": 0.35},
            {"type": "torus", "center": [4, 4, 4], "axis": [0.94, -0.24, -0.25], "major_radius": 3, "minor_radius": 0.35},
            {"type": "torus", "center": [4, 4, 4], "axis": [0.54, 0.84, -0.02], "major_radius": 3, "minor_radius": 0.35},
            {"type": "torus", "center": [4, 4, 4], "axis": [-0.21, -0.65, -0.73], "major_radius": 3, "minor_radius": 0.35}]},
          {"type": "sphere", "center": [4, 4, 6.5], "radius": 1.8}]},
        "lattice": {"sigma": 1.0, "cells": [8, 8, 8]}}},
      "objects": OBJECTS})";
    text.replace(text.find("OBJECTS"), 7, objects);
    return load_scene_text(text, "tori.json");
}

// Two instances, one turned, over a floor.
const Scene& tori_scene() {
    static const Scene s = tori_scene_with(R"([
        {"type": "instance", "primitive": "tori", "material": "m"},
        {"type": "instance", "primitive": "tori", "material": "m",
         "transform": [{"rotate": {"axis": [1, 2, 3], "angle_deg": 70}}, {"translate": [5, 3, -4]}]},
        {"type": "halfspace", "point": [0, 0, -6], "normal": [0, 0, 1], "material": "m"}])");
    return s;
}

// An image of s through `candidates` lattices.
Image8 render_candidates(const Scene& s) {
    test::TempDir dir;
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "candidates";
    const SceneLattices l = scene_lattices(s, cache, spec, false);
    const TracedScene lattice(s, [&](int i) { return l.shapes[static_cast<std::size_t>(i)]; });
    return render_exact(lattice, {}).display;
}

// A primitive that counts how it is asked: with some leaves switched off (pieces_spans), or
// whole (the lattice's fallback when a span leaves the ray's chord).
class CountingTree final : public Shape, public LatticeSource, public Pieces {
public:
    explicit CountingTree(const Shape& tree) : tree_(tree), source_(tree) {}
    mutable int whole = 0, pieces = 0;

    Bounds3 bounds() const override { return tree_.bounds(); }
    bool intersect(const Ray& r, double t0, double t1, Crossing& c) const override {
        ++whole;
        return tree_.intersect(r, t0, t1, c);
    }
    void spans(const Ray& r, SpanList& out) const override { ++whole, tree_.spans(r, out); }
    Vec3 normal(const Ray& r, const Crossing& c) const override { return tree_.normal(r, c); }
    bool inside(Vec3 p) const override { return tree_.inside(p); }
    bool names_surface(const Crossing& c) const override { return c.part == 0; }
    std::uint32_t surface_count() const override { return source_.surface_count(); }
    double intersect_cost() const override { return 1.0; }
    std::size_t piece_count() const override { return source_.piece_count(); }
    void piece_spheres(std::size_t i, std::vector<BoundingSphere>& out) const override {
        source_.piece_spheres(i, out);
    }
    void pieces_spans(std::span<const std::uint32_t> on, const Ray& r, SpanList& out) const override {
        ++pieces, source_.pieces_spans(on, r, out);
    }

private:
    const Shape& tree_;
    ShapeSource source_;  // the tree's (a CSG tree's: not the union of its pieces)
};

TEST(EncodingCandidates, CsgPrimitivesListTheirLeaves) {
    // Random rays through the lattice of a CSG of tori: the lattice evaluates the tree with the
    // leaves listed for the ray's pair alone, and answers as the whole tree does.
    const Primitive& p = tori_scene().primitives.at(0);
    const CountingTree counting(*p.shape);
    const Built b = build_for(tori_scene(), "candidates", 1, {}, &counting);
    counting.whole = counting.pieces = 0;  // rasterizing asked it whole
    const auto shared = std::shared_ptr<const LatticeTable>(b.table.get(), [](const LatticeTable*) {});
    const auto ls = make_lattice_shape(shared, b.ctx, 0.0);
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0, 1);
    int hits = 0, listed = 0, pairs = 0;
    for (int n = 0; n < 20000; ++n) {
        const Ray ray = ray_into({8, 8, 8}, rng);
        Crossing ce, cl;
        const bool exact = p.shape->intersect(ray, 0, kInfinity, ce);
        ASSERT_EQ(exact, ls->intersect(ray, 0, kInfinity, cl)) << n;
        if (exact) {
            ++hits;
            ASSERT_EQ(ce.t, cl.t) << n;
            ASSERT_EQ(ce.leaf, cl.leaf) << n;
        }
        const double t_mid = 30 + 8 * (u(rng) - 0.5);
        EXPECT_EQ(p.shape->occluded(ray, t_mid, kInfinity), ls->occluded(ray, t_mid, kInfinity)) << n;
        SpanList se, sl;
        p.shape->spans(ray, se);
        ls->spans(ray, sl);
        ASSERT_EQ(se.size(), sl.size()) << n;
        for (std::size_t k = 0; k < se.size(); ++k) ASSERT_EQ(se[k].out.t, sl[k].out.t) << n;
        LatticeFrame::Snap s;
        const LatticeFrame frame(b.ctx, 0.0);
        CandidateList list;
        if (frame.snap(ray, s) && b.table->candidates(s.a, s.b, list)) ++pairs, listed += list.count;
    }
    EXPECT_GT(hits, 5000);
    // Of five leaves, about three are listed a pair (3.2 when written): the others are off.
    EXPECT_LT(listed, 7 * pairs / 2);
    // The answers came from the listed leaves: every span stays in the box (the subtracted
    // sphere, which reaches out of it, only takes away).
    EXPECT_GT(counting.pieces, 3 * pairs / 2);
    EXPECT_EQ(counting.whole, 0);
}

TEST(EncodingCandidates, CsgPrimitivesRenderAsExact) {
    const Scene& s = tori_scene();
    const ImageDiffStats d =
        compare_images(render_exact(TracedScene(s), {}).display, render_candidates(s));
    EXPECT_EQ(d.max_abs_error, 0);
}

TEST(EncodingCandidates, CsgPrimitivesAsCsgLeavesRenderAsExact) {
    // The lattice's crossings name the primitive's surfaces: the cut faces of the subtracted
    // spheres (the primitive's and the object's) shade with their own normals and materials.
    const Scene s = tori_scene_with(R"([
        {"type": "csg", "op": "difference", "material": "m", "children": [
          {"type": "instance", "primitive": "tori",
           "transform": [{"rotate": {"axis": [0, 1, 0], "angle_deg": 200}}, {"translate": [8, 0, 8]}]},
          {"type": "sphere", "center": [5, 4, 6], "radius": 2.2, "material": "cut"}]},
        {"type": "halfspace", "point": [0, 0, -6], "normal": [0, 0, 1], "material": "m"}])");
    const Image8 exact = render_exact(TracedScene(s), {}).display;
    EXPECT_EQ(compare_images(exact, render_candidates(s)).max_abs_error, 0);
    std::size_t covered = 0;
    for (std::size_t i = 0; i + 2 < exact.rgb.size(); i += 3)
        covered += std::equal(exact.rgb.begin() + i, exact.rgb.begin() + i + 3, exact.rgb.begin()) ? 0 : 1;
    EXPECT_GT(covered, exact.rgb.size() / 3 / 10);
}

TEST(EncodingCandidates, OlderPayloadsAreRefusedCleanly) {
    // CAND1 (part sets as 64-bit masks, a shorter payload) and CAND2 (lists of primitives) are
    // no longer read: opened anyway, they throw, and never read past the payload.
    Built b = build("candidates", 1);
    for (const std::uint64_t old : {0x31444E4143'5441ull, 0x32444E4143'5441ull}) {
        std::memcpy(b.payload.data(), &old, 8);
        EXPECT_THROW(CandidatesTable(b.payload.data(), b.payload.size(), b.table->entries(), b.ctx),
                     std::runtime_error);
        EXPECT_THROW(CandidatesTable(b.payload.data(), 64, b.table->entries(), b.ctx),
                     std::runtime_error);
    }
}

TEST(EncodingCandidates, OlderCachedTablesAreRebuiltBeside) {
    // Tables of those payloads were written under layout 1, which their fingerprint (and so
    // their name in the cache) leaves out; today's layout is part of it. A cache holding one
    // builds the table anew beside it and renders.
    EXPECT_GT(find_encoding("candidates").layout, 1);
    test::TempDir dir;
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "candidates";
    const Scene& s = hair_scene();
    const TablePlan plan = plan_table(s.primitives.at(0), spec, s.file);
    const std::string path = cache.get(plan, false).path;
    // The file an older build left: the same table but for another fingerprint in its name.
    const std::string old = path.substr(0, path.size() - 20) + "0123456789abcdef.lht";
    std::filesystem::rename(path, old);
    const TableCache::Entry again = cache.get(plan, false);
    EXPECT_TRUE(again.built);
    EXPECT_EQ(again.path, path);
    ASSERT_TRUE(again.table);
    EXPECT_TRUE(std::filesystem::exists(old));
}

TEST(EncodingCandidates, BuildsStopAtTheirMemoryBudget) {
    // A table's lists grow with the parts near each pair, which the plan before a build cannot
    // foresee: past its budget the build stops with an input error, not an exhausted machine.
    const Primitive& p = hair_scene().primitives.at(0);
    const LatticeSpec& l = *p.lattice;
    const TableContext ctx{{l.cells[0] * 2, l.cells[1] * 2, l.cells[2] * 2}, l.sigma / 2, l.sigma,
                           p.shape.get()};
    EncodeOptions small;
    small.memory_budget = 20000;
    try {
        find_encoding("candidates").build({}, ctx, small);
        FAIL() << "built within 20 kB";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("more than the 20.0 kB of memory it may use"),
                  std::string::npos)
            << e.what();
    }
    EncodeOptions ample;
    ample.memory_budget = 100'000'000;
    const ByteBuffer payload = find_encoding("candidates").build({}, ctx, ample);
    EXPECT_EQ(payload.size(), find_encoding("candidates").build({}, ctx, {}).size());
}

TEST(EncodingCandidates, PlatesRenderAsExact) {
    test::TempDir dir;
    const TableCache cache(dir.path().string());
    TableSpec spec;
    spec.encoding = "candidates";
    for (const char* plate : {"plate2-thistle", "plate4-fuzzy-sphere-1000"}) {
        Scene s = load_scene(test::source_path(std::string("examples/") + plate + ".json"));
        s.camera.width = s.camera.height = 160;
        const SceneLattices l = scene_lattices(s, cache, spec, false);
        const TracedScene lattice(s, [&](int i) { return l.shapes[static_cast<std::size_t>(i)]; });
        const ImageDiffStats d = compare_images(render_exact(TracedScene(s), {}).display,
                                                render_exact(lattice, {}).display);
        EXPECT_EQ(d.max_abs_error, 0) << plate;
    }
}

}  // namespace
}  // namespace lat
