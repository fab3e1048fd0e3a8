// Triangle meshes: a rendered mesh scene against an independent brute-force tracer written here
// from docs/scene-format.md (long double, every triangle tested for every ray), a closed mesh
// as a CSG leaf against the same solid made of half-spaces, and the file checks.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <vector>

#include "geometry/triangle_mesh.h"
#include "input_error.h"
#include "io/image_compare.h"
#include "io/mesh_file.h"
#include "render/modes/integrators.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"

namespace lat {
namespace {

// ---- An independent tracer for one mesh over a ground plane z = 0 -------------------------
using R = long double;
struct V {
    R x = 0, y = 0, z = 0;
};
V operator+(V a, V b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V operator-(V a, V b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V operator*(R s, V a) { return {s * a.x, s * a.y, s * a.z}; }
R dotv(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V crossv(V a, V b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V unit(V a) { return (1 / std::sqrt(dotv(a, a))) * a; }

struct RefMesh {
    std::vector<V> p, n;  // per vertex
    std::vector<std::array<int, 3>> tri;
};

// A torus around z (radii 1 and 0.4), lifted to z = 0.6 and tilted, as a grid of quads split
// in two: non-convex, so it shadows itself.
RefMesh torus_mesh(int nu, int nv) {
    RefMesh m;
    const R tilt = 0.5L;
    auto place = [&](V q) {  // rotate about x by `tilt`, then lift
        return V{q.x, std::cos(tilt) * q.y - std::sin(tilt) * q.z,
                 std::sin(tilt) * q.y + std::cos(tilt) * q.z + 0.75L};
    };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const R u = 2 * M_PIl * i / nu, v = 2 * M_PIl * j / nv;
            const V c{std::cos(u), std::sin(u), 0};
            const V nn{std::cos(v) * c.x, std::cos(v) * c.y, std::sin(v)};
            m.p.push_back(place(c + 0.4L * nn));
            m.n.push_back(place(nn) - place(V{}));
        }
    auto id = [&](int i, int j) { return ((i + nu) % nu) * nv + (j + nv) % nv; };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            m.tri.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            m.tri.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return m;
}

std::string to_obj(const RefMesh& m, bool normals) {
    std::ostringstream o;
    o.precision(17);
    for (const V& p : m.p) o << "v " << double(p.x) << ' ' << double(p.y) << ' ' << double(p.z) << '\n';
    if (normals)
        for (const V& n : m.n) o << "vn " << double(n.x) << ' ' << double(n.y) << ' ' << double(n.z) << '\n';
    for (const auto& t : m.tri) {
        o << 'f';
        for (int k : t) o << ' ' << k + 1 << (normals ? "//" + std::to_string(k + 1) : "");
        o << '\n';
    }
    return o.str();
}

std::string to_ply(const RefMesh& m) {
    std::ostringstream o;
    o.precision(17);
    o << "ply\nformat ascii 1.0\nelement vertex " << m.p.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << m.tri.size()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const V& p : m.p) o << double(p.x) << ' ' << double(p.y) << ' ' << double(p.z) << '\n';
    for (const auto& t : m.tri) o << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    return o.str();
}

// Closest triangle hit with t > tmin: Moller-Trumbore in long double.
bool ref_hit(const RefMesh& m, V o, V d, R tmin, R tmax, R& t, int& tri, R& bu, R& bv) {
    bool found = false;
    for (std::size_t k = 0; k < m.tri.size(); ++k) {
        const V a = m.p[m.tri[k][0]], e1 = m.p[m.tri[k][1]] - a, e2 = m.p[m.tri[k][2]] - a;
        const V pv = crossv(d, e2);
        const R det = dotv(e1, pv);
        if (det == 0) continue;
        const V s = o - a;
        const R u = dotv(s, pv) / det;
        if (u < 0 || u > 1) continue;
        const V q = crossv(s, e1);
        const R v = dotv(d, q) / det;
        if (v < 0 || u + v > 1) continue;
        const R tt = dotv(e2, q) / det;
        if (tt > tmin && tt < tmax) {
            tmax = t = tt;
            tri = static_cast<int>(k);
            bu = u;
            bv = v;
            found = true;
        }
    }
    return found;
}

// The unit shading normal of triangle `tri` at barycentrics (u, v), in world coordinates.
using NormalAt = std::function<V(int tri, R u, R v)>;

// Per-vertex normals blended, or flat faces (each triangle's own normal) when empty.
NormalAt vertex_normals(const RefMesh& m, std::vector<V> normals) {
    return [&m, normals = std::move(normals)](int tri, R u, R v) {
        const auto& k = m.tri[tri];
        if (normals.empty()) return unit(crossv(m.p[k[1]] - m.p[k[0]], m.p[k[2]] - m.p[k[0]]));
        return unit((1 - u - v) * normals[k[0]] + u * normals[k[1]] + v * normals[k[2]]);
    };
}

// The documented shading rule with the scene below: material m, ground z = 0 of material g.
Image8 reference_image(const RefMesh& m, const NormalAt& normal_at, int w, int h) {
    const V eye{3.2L, -4.5L, 2.6L}, look{0, 0, 0.6L}, up{0, 0, 1};
    const V W = unit(look - eye), U = unit(crossv(W, up)), Vv = crossv(U, W);
    const R th = std::tan(30.0L * M_PIl / 360), aspect = R(w) / h;
    const std::array<V, 2> lights{V{4, -3, 6}, V{-5, -4, 3}};
    const std::array<R, 2> intensity{0.8L, 0.4L};
    const V col_m{0.9L, 0.6L, 0.3L}, col_g{0.5L, 0.6L, 0.5L};
    Image8 img;
    img.width = w;
    img.height = h;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const V d = unit(W + ((2 * (i + 0.5L) / w - 1) * aspect * th) * U +
                             ((1 - 2 * (j + 0.5L) / h) * th) * Vv);
            R t = 1e30L, bu = 0, bv = 0;
            int tri = -1;
            const bool mesh = ref_hit(m, eye, d, 0, 1e30L, t, tri, bu, bv);
            const R tg = d.z < 0 ? -eye.z / d.z : 1e30L;
            V c{0.1L, 0.1L, 0.2L};  // background
            if (mesh || tg < 1e30L) {
                const bool on_mesh = mesh && t < tg;
                const R tt = on_mesh ? t : tg;
                const V p = eye + tt * d;
                V n{0, 0, 1};
                V col = col_g;
                R ks = 0.1L;
                if (on_mesh) {
                    n = normal_at(tri, bu, bv);
                    col = col_m;
                    ks = 0.5L;
                }
                if (dotv(n, d) > 0) n = -1 * n;
                c = 0.1L * col;
                for (std::size_t l = 0; l < 2; ++l) {
                    const V tl = lights[l] - p;
                    const R dist = std::sqrt(dotv(tl, tl));
                    const V L = (1 / dist) * tl;
                    R t2, u2, v2;
                    int tri2;
                    const R eps = 1e-6L;
                    if (ref_hit(m, p, L, eps, dist, t2, tri2, u2, v2)) continue;
                    const R nl = dotv(n, L);
                    const V Rr = 2 * nl * n - L;
                    const R rv = std::max<R>(0, -dotv(Rr, d));
                    const R spec = ks * std::pow(rv, 20.0L);
                    c = c + intensity[l] * ((0.7L * std::max<R>(0, nl)) * col + V{spec, spec, spec});
                }
            }
            for (R ch : {c.x, c.y, c.z}) img.rgb.push_back(to_byte(static_cast<double>(ch)));
        }
    return img;
}

// Vertices are read as floats: the reference traces the same rounded vertices.
RefMesh float_vertices(RefMesh m) {
    for (V& p : m.p) p = {R(float(p.x)), R(float(p.y)), R(float(p.z))};
    return m;
}

std::string scene_json(const std::string& file, const std::string& mesh_fields = "") {
    return R"({
  "camera": {"eye": [3.2, -4.5, 2.6], "look_at": [0, 0, 0.6], "fov_y_deg": 30, "width": 160, "height": 120},
  "background": [0.1, 0.1, 0.2], "ambient": 1,
  "lights": [{"position": [4, -3, 6], "intensity": 0.8}, {"position": [-5, -4, 3], "intensity": 0.4}],
  "materials": {"m": {"color": [0.9, 0.6, 0.3], "ka": 0.1, "kd": 0.7, "ks": 0.5, "shininess": 20},
                "g": {"color": [0.5, 0.6, 0.5], "ka": 0.1, "kd": 0.7, "ks": 0.1, "shininess": 20}},
  "objects": [{"type": "mesh", "file": ")" + file + R"(", "material": "m")" + mesh_fields + R"(},
              {"type": "halfspace", "normal": [0, 0, 1], "material": "g"}]})";
}

void expect_close(const Image8& got, const Image8& want) {
    const ImageDiffStats st = compare_images(got, want);
    EXPECT_GE(st.psnr_db, 40.0);
    EXPECT_LT(st.share_over_8, 0.005);
    // And the mesh is really there: not all background or ground.
    std::size_t orange = 0;
    for (std::size_t k = 0; k + 2 < got.rgb.size(); k += 3) orange += got.rgb[k] > got.rgb[k + 2] + 40;
    EXPECT_GT(orange, got.rgb.size() / 3 / 20);
}

TEST(Mesh, ObjWithNormalsMatchesBruteForceTracer) {
    const test::TempDir dir;
    const RefMesh m = torus_mesh(48, 24);
    test::spit(dir.file("torus.obj"), to_obj(m, true));
    const std::string scene_path = dir.file("scene.json");
    test::spit(scene_path, scene_json("torus.obj"));  // relative to the scene file
    const Scene s = load_scene(scene_path);
    const Image8 got = render_exact(TracedScene(s), {}).display;
    std::vector<V> n;
    for (const V& x : m.n) n.push_back(unit(x));
    const RefMesh f = float_vertices(m);
    expect_close(got, reference_image(f, vertex_normals(f, n), 160, 120));
}

// Without normals in the file the faces are flat; with "smooth": true each vertex normal is the
// sum of its faces' cross products.
TEST(Mesh, PlyWithoutNormalsIsFlatUnlessSmooth) {
    const test::TempDir dir;
    const RefMesh m = torus_mesh(40, 20);
    test::spit(dir.file("torus.ply"), to_ply(m));
    test::spit(dir.file("flat.json"), scene_json("torus.ply"));
    test::spit(dir.file("smooth.json"), scene_json("torus.ply", R"(, "smooth": true)"));
    const Image8 flat = render_exact(TracedScene(load_scene(dir.file("flat.json"))), {}).display;
    const Image8 smooth = render_exact(TracedScene(load_scene(dir.file("smooth.json"))), {}).display;
    std::vector<V> n(m.p.size());
    for (const auto& t : m.tri) {
        const V f = crossv(m.p[t[1]] - m.p[t[0]], m.p[t[2]] - m.p[t[0]]);
        for (int k : t) n[k] = n[k] + f;
    }
    for (V& x : n) x = unit(x);
    const RefMesh f = float_vertices(m);
    expect_close(flat, reference_image(f, vertex_normals(f, {}), 160, 120));
    expect_close(smooth, reference_image(f, vertex_normals(f, n), 160, 120));
    EXPECT_LT(compare_images(flat, smooth).psnr_db, 40.0);  // the two rules differ visibly
}

// Two objects in one OBJ over the same vertices, the first with normals and the second without,
// under a non-uniform scale: the first is smooth (its unit normals blended in the mesh's own
// coordinates, then carried by the inverse transpose), the second flat, as documented.
TEST(Mesh, PerObjectNormalsUnderANonUniformScale) {
    const test::TempDir dir;
    const RefMesh m = torus_mesh(40, 20);
    std::ostringstream o;
    o.precision(17);
    o << "o smooth\n";
    for (const V& p : m.p) o << "v " << double(p.x) << ' ' << double(p.y) << ' ' << double(p.z) << '\n';
    for (const V& n : m.n) o << "vn " << double(n.x) << ' ' << double(n.y) << ' ' << double(n.z) << '\n';
    const std::size_t half = m.tri.size() / 2;
    for (std::size_t t = 0; t < m.tri.size(); ++t) {
        if (t == half) o << "o flat\n";
        o << 'f';
        for (int k : m.tri[t]) o << ' ' << k + 1 << (t < half ? "//" + std::to_string(k + 1) : "");
        o << '\n';
    }
    test::spit(dir.file("two.obj"), o.str());
    test::spit(dir.file("scene.json"),
               scene_json("two.obj", R"(, "transform": [{"scale": [1.3, 0.8, 1.1]}, {"translate": [0.1, 0, -0.2]}])"));
    const Scene scene = load_scene(dir.file("scene.json"));
    const auto& mesh = dynamic_cast<const TriangleMeshShape&>(*scene.objects[0].shape);
    for (const std::size_t t : {std::size_t{0}, half - 1, half, m.tri.size() - 1}) {
        const Vec3 n = mesh.shading_normal(t, 0.2, 0.3), f = mesh.face_normal(t);
        if (t < half)
            EXPECT_GT(length(n - f), 1e-3) << "triangle " << t << " of the object with normals";
        else
            EXPECT_EQ(n, f) << "triangle " << t << " of the object without normals";
    }
    const Image8 got = render_exact(TracedScene(scene), {}).display;

    const V s{1.3L, 0.8L, 1.1L}, shift{0.1L, 0, -0.2L};
    RefMesh world = float_vertices(m);
    for (V& p : world.p) p = V{s.x * p.x, s.y * p.y, s.z * p.z} + shift;
    const NormalAt normal_at = [&](int tri, R u, R v) {
        const auto& k = world.tri[tri];
        if (std::size_t(tri) >= half) return unit(crossv(world.p[k[1]] - world.p[k[0]], world.p[k[2]] - world.p[k[0]]));
        const V a = unit(m.n[k[0]]), b = unit(m.n[k[1]]), c = unit(m.n[k[2]]);
        const V blend = (1 - u - v) * a + u * b + v * c;
        return unit(V{blend.x / s.x, blend.y / s.y, blend.z / s.z});
    };
    expect_close(got, reference_image(world, normal_at, 160, 120));
}

// A closed box mesh with per-face normals (so 24 vertices: closed by position, not by index).
std::string box_obj() {
    return "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
           "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n"
           "f 1//1 3//1 2//1\nf 1//1 4//1 3//1\nf 5//2 6//2 7//2\nf 5//2 7//2 8//2\n"
           "f 1//3 2//3 6//3\nf 1//3 6//3 5//3\nf 4//4 8//4 7//4\nf 4//4 7//4 3//4\n"
           "f 1//5 5//5 8//5\nf 1//5 8//5 4//5\nf 2//6 3//6 7//6\nf 2//6 7//6 6//6\n";
}

TEST(Mesh, ClosedMeshIsACsgLeafLikeTheSameSolidOfHalfspaces) {
    const test::TempDir dir;
    test::spit(dir.file("box.obj"), box_obj());
    auto scene = [](const std::string& cutter) {
        return R"({"camera": {"eye": [3, -4, 2.5], "look_at": [0, 0, 0], "fov_y_deg": 35, "width": 96, "height": 96},
          "lights": [{"position": [4, -3, 6]}],
          "materials": {"a": {"color": [0.8, 0.3, 0.2]}, "b": {"color": [0.2, 0.5, 0.8]}},
          "objects": [{"type": "csg", "op": "difference", "children": [
             {"type": "sphere", "radius": 1.3, "material": "a"},
             )" + cutter + R"(]}]})";
    };
    const std::string box = R"({"type": "mesh", "file": "box.obj", "material": "b",
        "transform": [{"scale": 0.8}, {"translate": [0.6, -0.6, 0.6]}]})";
    std::string halfspaces = R"({"type": "csg", "op": "intersection", "material": "b",
        "transform": [{"scale": 0.8}, {"translate": [0.6, -0.6, 0.6]}], "children": [)";
    const char* normals[] = {"[1,0,0]", "[-1,0,0]", "[0,1,0]", "[0,-1,0]", "[0,0,1]", "[0,0,-1]"};
    for (int k = 0; k < 6; ++k)
        halfspaces += std::string(k ? "," : "") + R"({"type": "halfspace", "normal": )" +
                      normals[k] + R"(, "point": )" + normals[k] + "}";
    halfspaces += "]}";
    test::spit(dir.file("mesh.json"), scene(box));
    test::spit(dir.file("exact.json"), scene(halfspaces));
    const Scene a = load_scene(dir.file("mesh.json")), b = load_scene(dir.file("exact.json"));
    const Image8 ia = render_exact(TracedScene(a), {}).display;
    const Image8 ib = render_exact(TracedScene(b), {}).display;
    const ImageDiffStats st = compare_images(ia, ib);
    EXPECT_GE(st.psnr_db, 40.0);
    EXPECT_LT(st.share_over_8, 0.005);
}

TEST(Mesh, InsideByParityAndClosedness) {
    const test::TempDir dir;
    test::spit(dir.file("box.obj"), box_obj());
    const MeshData d = read_mesh_file(dir.file("box.obj"));
    const TriangleMeshShape box(d.positions, d.triangles, d.normals);
    EXPECT_TRUE(box.closed());
    EXPECT_TRUE(box.inside({0, 0, 0}));
    EXPECT_TRUE(box.inside({0.99, -0.99, 0.5}));
    EXPECT_FALSE(box.inside({1.01, 0, 0}));
    EXPECT_FALSE(box.inside({0, 0, -3}));
    // A ray along an edge-crossing diagonal still gives one span of the right length.
    SpanList s;
    box.spans({{-3, -3, 0}, {1, 1, 0}}, s);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_NEAR(s[0].in.t, 2, 1e-12);
    EXPECT_NEAR(s[0].out.t, 4, 1e-12);
    // Drop two triangles: open.
    auto tris = d.triangles;
    tris.resize(10);
    EXPECT_FALSE(TriangleMeshShape(d.positions, tris).closed());
}

TEST(Mesh, BadFilesGiveOneMessage) {
    const test::TempDir dir;
    auto error_for = [&](const std::string& name, const std::string& text) {
        test::spit(dir.file(name), text);
        return test::error_of([&] { read_mesh_file(dir.file(name)); });
    };
    EXPECT_NE(test::error_of([&] { read_mesh_file(dir.file("none.obj")); })
                  .find("none.obj: cannot open mesh file: No such file"),
              std::string::npos);
    EXPECT_NE(error_for("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n").find("no triangles"), std::string::npos);
    EXPECT_NE(error_for("garbage.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 99999999\n"
                                       "property float x\nend_header\n\x01\x02")
                  .find("garbage.ply: "),
              std::string::npos);
    MeshData m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}};
    m.triangles = {{0, 1, 2}};
    EXPECT_NE(test::error_of([&] { check_mesh(m, "m"); }).find("m: vertex 2 is not finite"), std::string::npos);
    m.positions[2] = {0, 1, 0};
    m.triangles = {{0, 1, 7}};
    EXPECT_NE(test::error_of([&] { check_mesh(m, "m"); }).find("triangle 0 refers to vertex 7"), std::string::npos);
}

TEST(Mesh, OpenMeshInCsgIsAnInputError) {
    const test::TempDir dir;
    test::spit(dir.file("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    test::spit(dir.file("s.json"), R"({"camera": {"eye": [0, -5, 0], "look_at": [0, 0, 0], "fov_y_deg": 30, "width": 8, "height": 8},
      "materials": {"a": {}},
      "objects": [{"type": "csg", "op": "union", "material": "a", "children": [
        {"type": "sphere", "radius": 1}, {"type": "mesh", "file": "tri.obj"}]}]})");
    const std::string e = test::error_of([&] { load_scene(dir.file("s.json")); });
    EXPECT_NE(e.find("s.json: objects[0].children[1].file: an open mesh cannot be a csg leaf"),
              std::string::npos)
        << e;
}

}  // namespace
}  // namespace lat
