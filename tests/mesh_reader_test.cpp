// The OBJ and PLY readers (io/mesh_file.h): formats and encodings agree, normals belong to the
// corners that name them, faces without normals are flat, and bad files give one message in
// our words, with control bytes escaped.
#include <sys/stat.h>

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "geometry/triangle_mesh.h"
#include "input_error.h"
#include "io/mesh_file.h"
#include "temp_dir.h"

namespace lat {
namespace {

const std::vector<Vec3> kCube = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                 {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
// Quads wound outwards, as a user would write them: 8 shared corners, no normals.
const std::vector<std::array<int, 4>> kQuads = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                                {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};

std::string cube_obj() {
    std::string s = "# a cube without normals\n";
    for (const Vec3& p : kCube)
        s += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
    for (const auto& q : kQuads)
        s += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " +
             std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
    return s;
}

template <class T>
void put(std::string& out, T v, bool big) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    if (big)
        for (std::size_t i = 0; i < sizeof v / 2; ++i) std::swap(b[i], b[sizeof v - 1 - i]);
    out.append(b, sizeof v);
}

std::string cube_ply(const std::string& format) {
    std::string s = "ply\nformat " + format + " 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
    const bool big = format == "binary_big_endian";
    for (const Vec3& p : kCube) {
        if (format == "ascii") {
            s += std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
        } else {
            for (double c : {p.x, p.y, p.z}) put(s, static_cast<float>(c), big);
        }
    }
    for (const auto& q : kQuads) {
        if (format == "ascii") {
            s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
                 " " + std::to_string(q[3]) + "\n";
        } else {
            s += '\x04';
            for (int k : q) put(s, static_cast<std::int32_t>(k), big);
        }
    }
    return s;
}

// The shading normal at points spread over each face of the cube equals the face's outward
// normal: no smoothing across the creases of a file without normals.
void expect_flat_cube(const MeshData& d) {
    const TriangleMeshShape cube(d.positions, d.triangles, d.normals);
    ASSERT_TRUE(cube.closed());
    const Vec3 axes[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    int checked = 0;
    for (const Vec3& n : axes) {
        const Vec3 u = std::abs(n.x) > 0 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
        const Vec3 w = cross(n, u);
        for (double a = -0.95; a <= 0.95; a += 0.19)
            for (double b = -0.95; b <= 0.95; b += 0.19) {
                const Vec3 target = n + a * u + b * w;
                const Ray r{target + 3.0 * n, -1.0 * n};
                Crossing c;
                ASSERT_TRUE(cube.intersect(r, 0, kInfinity, c));
                EXPECT_NEAR(c.t, 3, 1e-12);
                const Vec3 got = cube.normal(r, c);
                EXPECT_NEAR(length(got - n), 0, 1e-12) << "at " << target.x << " " << target.y << " " << target.z;
                ++checked;
            }
    }
    EXPECT_EQ(checked, 6 * 11 * 11);
}

TEST(MeshReader, CubeWithoutNormalsIsFlatInEveryFormat) {
    expect_flat_cube(parse_obj(cube_obj(), "cube.obj"));
    for (const char* f : {"ascii", "binary_little_endian", "binary_big_endian"}) {
        SCOPED_TRACE(f);
        const MeshData d = parse_ply(cube_ply(f), "cube.ply");
        EXPECT_EQ(d.positions.size(), 8u);
        EXPECT_EQ(d.triangles.size(), 12u);
        EXPECT_TRUE(d.normals.empty());
        expect_flat_cube(d);
    }
    // Smoothing is asked for, not assumed: the same cube smooth has round corners.
    const MeshData d = parse_obj(cube_obj(), "cube.obj");
    const TriangleMeshShape round(d.positions, d.triangles, d.normals, true);
    const Ray r{{0.9, 0.9, 4}, {0, 0, -1}};
    Crossing c;
    ASSERT_TRUE(round.intersect(r, 0, kInfinity, c));
    EXPECT_GT(length(round.normal(r, c) - Vec3{0, 0, 1}), 0.3);
}

// Two objects, one with normals (tilted, so that they show) and one without: each keeps its own.
TEST(MeshReader, NormalsBelongToTheCornersThatNameThem) {
    const std::string obj =
        "o tilted\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0.6 0 0.8\nf 1//1 2//1 3//1\n"
        "o plain\nv 0 0 5\nv 1 0 5\nv 0 1 5\nf 4 5 6\n"
        "o shared\nf 1 2 3\n";  // the first triangle's vertices again, without normals
    const MeshData d = parse_obj(obj, "two.obj");
    ASSERT_EQ(d.triangles.size(), 3u);
    ASSERT_EQ(d.normals.size(), d.positions.size());
    const TriangleMeshShape m(d.positions, d.triangles, d.normals);
    EXPECT_NEAR(length(m.shading_normal(0, 0.2, 0.3) - Vec3{0.6, 0, 0.8}), 0, 1e-6);
    EXPECT_EQ(m.shading_normal(1, 0.2, 0.3), (Vec3{0, 0, 1}));
    EXPECT_EQ(m.shading_normal(2, 0.2, 0.3), (Vec3{0, 0, 1}));
}

TEST(MeshReader, ObjSyntax) {
    // CR, CR LF and LF line ends; negative indices; v/vt, v//vn, v/vt/vn corners; comments; colours.
    const MeshData d = parse_obj("v 0 0 0 1 0 0\rv 1 0 0\r\nv 1 1 0 # comment\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                                 "f -4/1 -3/1/1 -2//1 -1\nf 1 2 3 4 1\n",
                                 "s.obj");
    EXPECT_EQ(d.positions.size(), 6u);  // (v, vn) pairs: 1, 2/1, 3/1, 4, and 2 and 3 without vn
    EXPECT_EQ(d.triangles.size(), 5u);  // a quad and a pentagon, as fans
    // A concave quad is split along the diagonal through its reflex corner.
    const MeshData q = parse_obj("v 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\nf 1 2 3 4\n", "q.obj");
    ASSERT_EQ(q.triangles.size(), 2u);
    EXPECT_EQ(q.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(q.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
    const MeshData r = parse_obj("v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1.5 0.5 0\nf 1 2 3 4\n", "r.obj");
    EXPECT_EQ(r.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 3}));
    EXPECT_EQ(r.triangles[1], (std::array<std::uint32_t, 3>{1, 2, 3}));
}

// A file is read a piece at a time: lines, CR LF pairs and numbers cut across pieces read as
// they do whole, and only the current line is held.
TEST(MeshReader, ObjInPieces) {
    const std::string text = "v 0 0 0\r\nv 1.5 0 0\rv 0 1 0\r\nvn 0 0 1\n\nf 1//1 2//1 3//1\r\nf 1 2 3";
    const MeshData whole = parse_obj(text, "m.obj");
    auto in_pieces = [](const std::string& t, std::size_t size) {
        std::size_t at = 0;
        return parse_obj_pieces(
            [&] {
                const std::string_view piece = std::string_view(t).substr(at, size);
                at += piece.size();
                return piece;
            },
            "m.obj");
    };
    for (std::size_t size : {1, 2, 3, 7}) {
        const MeshData d = in_pieces(text, size);
        EXPECT_EQ(d.positions, whole.positions) << size;
        EXPECT_EQ(d.triangles, whole.triangles) << size;
        EXPECT_EQ(d.normals, whole.normals) << size;
        // Lines are counted the same way (a CR LF cut in two is one line end).
        EXPECT_EQ(test::error_of([&] { in_pieces(text + "\r\nf 1 2 9\n", size); }),
                  "m.obj: line 8: face 3 refers to vertex 9, but 3 vertices come before it")
            << size;
    }
    EXPECT_EQ(whole.triangles.size(), 2u);
    EXPECT_EQ(whole.positions[1], (Vec3{1.5, 0, 0}));
    // A line without end is refused once it is longer than the limit, not held whole.
    const std::string endless(kMaxObjLineBytes + 1, 'x');
    EXPECT_EQ(test::error_of([&] { parse_obj(endless, "m.obj"); }),
              "m.obj: line 1 is longer than " + std::to_string(kMaxObjLineBytes) + " bytes");
    // A file of many pieces (the reader takes 1 MiB at a time).
    const test::TempDir dir;
    std::string big;
    while (big.size() < (std::size_t{3} << 20)) big += "v 0.25 0.5 0.75\r\n";
    test::spit(dir.file("big.obj"), big + "f 1 2 -1\r\n");
    const MeshData b = read_mesh_file(dir.file("big.obj"));
    EXPECT_EQ(b.triangles.size(), 1u);
    EXPECT_EQ(b.positions[2], (Vec3{0.25, 0.5, 0.75}));
}

std::string error_obj(const std::string& text) {
    return test::error_of([&] { parse_obj(text, "m.obj"); });
}
std::string error_ply(const std::string& text) {
    return test::error_of([&] { parse_ply(text, "m.ply"); });
}

TEST(MeshReader, ObjMessages) {
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    EXPECT_EQ(error_obj(tri + "f 1 2\nl 1 2\np 3\n"),
              "m.obj: the mesh has no triangles: line 4: face 1 has 2 vertices, and points and lines are dropped");
    EXPECT_EQ(error_obj(tri + "f 1 2\nf 1 2 3\n"), "");  // the line is dropped, the triangle kept
    EXPECT_EQ(error_obj(tri + "f 1 2 4\n"), "m.obj: line 4: face 1 refers to vertex 4, but 3 vertices come before it");
    EXPECT_EQ(error_obj(tri + "f 1 2 -4\n"), "m.obj: line 4: face 1 refers to vertex -4, but 3 vertices come before it");
    EXPECT_EQ(error_obj(tri + "f 1//1 2 3\n"), "m.obj: line 4: face 1 refers to normal 1, but 0 normals come before it");
    EXPECT_EQ(error_obj(tri + "f 0 1 2\n"), "m.obj: line 4: face 1: '0' is not a vertex index (1, 2, ... or -1, -2, ...)");
    EXPECT_EQ(error_obj("v 0 0\n"), "m.obj: line 1: a vertex (v) has 2 numbers, not 3 to 7");
    EXPECT_EQ(error_obj("v 0 0 1e39\n"), "m.obj: line 1: '1e39' is not a finite number");
    EXPECT_EQ(error_obj("v 0 0 1e-50\n" + std::string("v 1 0 0\nv 0 1 0\nf 1 2 3\n")), "");  // underflow is 0
    // Control bytes are escaped (a NUL does not cut the message, a CR does not overwrite it),
    // and a long token is capped.
    EXPECT_EQ(error_obj(std::string("v 0 0 1\0\x1b[2J\n", 13)), "m.obj: line 1: '1\\x00\\x1b[2J' is not a finite number");
    const std::string e = error_obj("v 0 0 " + std::string(100000, '7') + "x\n");
    EXPECT_LT(e.size(), 120u) << e;
    EXPECT_NE(e.find("7777...' is not a finite number"), std::string::npos) << e;
}

std::string ply_head(const std::string& format, int vertices, int faces) {
    return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
           "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
           "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST(MeshReader, PlyMessages) {
    const std::string tri = "0 0 0\n1 0 0\n0 1 0\n";
    // Faces of fewer than 3 vertices are dropped; the file's triangle stays.
    EXPECT_EQ(parse_ply(ply_head("ascii", 3, 3) + tri + "0\n2 0 1\n3 0 1 2\n", "m.ply").triangles.size(), 1u);
    EXPECT_EQ(error_ply(ply_head("ascii", 3, 2) + tri + "0\n2 0 1\n"),
              "m.ply: the mesh has no triangles: line 13: face 1 has 0 vertices, and points and lines are dropped");
    // A binary file cut short says how far it got.
    std::string cut = ply_head("binary_little_endian", 40, 2);
    for (int k = 0; k < 12 * 3 + 1; ++k) put(cut, 0.5f, false);
    EXPECT_EQ(error_ply(cut), "m.ply: the file ends after 12 of 40 vertices");
    std::string claim = ply_head("binary_little_endian", 3, 1);
    claim.replace(claim.find("uchar int"), 9, "int int");
    for (int k = 0; k < 9; ++k) put(claim, 0.0f, false);
    put(claim, std::int32_t{1340000000}, false);
    EXPECT_EQ(error_ply(claim + std::string(12, '\0')),
              "m.ply: the file ends after 0 of 1 faces: face 1 lists 1340000000 vertex_indices, more "
              "than the rest of the file holds");
    EXPECT_EQ(error_ply(ply_head("ascii", 3, 1) + tri + "3 0 1 3\n"),
              "m.ply: line 13: face 1 refers to vertex 3, but the file's vertices are 0 to 2");
    // The header: every way around its checks found by fuzzing is refused up front.
    std::string nul = ply_head("ascii", 3, 1) + tri + "3 0 1 2\n";
    nul[nul.find("float y") + 5] = '\0';
    EXPECT_EQ(error_ply(nul), "m.ply: line 5: the PLY header holds the byte \\x00, which is not text");
    std::string cr = ply_head("ascii", 99999999, 1);
    for (char& c : cr) c = c == '\n' ? '\r' : c;
    EXPECT_EQ(error_ply(cr), "m.ply: the PLY header's lines end in CR alone; they must end in LF or CR LF");
    EXPECT_EQ(error_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_headerx\n"),
              "m.ply: line 5: 'end_headerx' is not a PLY header keyword");
    EXPECT_EQ(error_ply("ply\nformat ascii 1.0\nelement vertex 3\n"),
              "m.ply: the file ends in the PLY header, before its end_header line");
    std::string many = "ply\nformat ascii 1.0\n";
    for (int k = 0; k < 5000; ++k) many += "comment padding padding\n";
    EXPECT_EQ(error_ply(many + "end_header\n"),
              "m.ply: no end_header line in the first 65536 bytes of the PLY header");
    EXPECT_EQ(error_ply("ply\nformat ascii 1.0\nelement 300000000\nproperty float x\nend_header\n"),
              "m.ply: line 3: an element line must be 'element <name> <count>'");
    EXPECT_EQ(error_ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement vertex 2\n"),
              "m.ply: line 5: a second element 'vertex'");
    EXPECT_EQ(error_ply(ply_head("ascii", 40000000, 1)), "m.ply: 40000000 vertices is over the limit of 30000000");
}

// Files, not bytes: the format from the first bytes or the name, and special files refused.
TEST(MeshReader, Files) {
    const test::TempDir dir;
    test::spit(dir.file("cube.mesh"), cube_ply("ascii"));  // "ply" first: read as PLY
    EXPECT_EQ(read_mesh_file(dir.file("cube.mesh")).triangles.size(), 12u);
    test::spit(dir.file("cube.OBJ"), cube_obj());
    EXPECT_EQ(read_mesh_file(dir.file("cube.OBJ")).triangles.size(), 12u);
    test::spit(dir.file("cube.stl"), "solid x\nendsolid x\n");
    EXPECT_NE(test::error_of([&] { read_mesh_file(dir.file("cube.stl")); }).find("not a mesh file this program reads"),
              std::string::npos);
    ASSERT_EQ(::mkfifo(dir.file("fifo.obj").c_str(), 0600), 0);
    EXPECT_EQ(test::error_of([&] { read_mesh_file(dir.file("fifo.obj")); }),
              dir.file("fifo.obj") + ": cannot open mesh file: it is a FIFO, not a regular file");
    EXPECT_EQ(test::error_of([&] { read_mesh_file("/dev/zero"); }),
              "/dev/zero: cannot open mesh file: it is a device, not a regular file");
    // The material files an OBJ names are never opened.
    test::spit(dir.file("m.obj"), "mtllib fifo.obj\nusemtl a\n" + cube_obj());
    EXPECT_EQ(read_mesh_file(dir.file("m.obj")).triangles.size(), 12u);
}

}  // namespace
}  // namespace lat
