// Wavefront OBJ: the geometry statements (v, vn, f) strictly, everything else skipped. Texture
// coordinates are only counted (so that face corners naming them are checked), points (p) and
// lines (l) are dropped, and material files (mtllib, usemtl) are ignored without being opened:
// the scene gives the material. Lines end in LF, CR LF or CR alone; '#' starts a comment.
//
// A face corner is v, v/vt, v//vn or v/vt/vn, indices from 1 or negative (counted back from
// the last one read), referring to what comes before it in the file. Each distinct (v, vn)
// pair becomes one vertex of the mesh, so normals belong to the corners that name them: an
// object without vn next to one with them keeps its flat faces, the other its normals.
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "io/mesh_builder.h"
#include "io/mesh_file.h"
#include "util/error.h"

namespace lat {
namespace {

using mesh_io::fail;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }

// The line's whitespace-separated tokens, one at a time.
struct Tokens {
    std::string_view rest;
    bool next(std::string_view& tok) {
        std::size_t i = 0;
        while (i < rest.size() && is_space(rest[i])) ++i;
        std::size_t j = i;
        while (j < rest.size() && !is_space(rest[j])) ++j;
        tok = rest.substr(i, j - i);
        rest.remove_prefix(j);
        return !tok.empty();
    }
};

class ObjReader {
public:
    explicit ObjReader(const std::string& name) : name_(name), mesh_(name, [this] { return where(); }) {}

    // The next piece of the text. A line that runs past its end waits for the next piece (at
    // most kMaxObjLineBytes of it is kept); a CR at its end may pair with an LF starting the next.
    void feed(std::string_view piece) {
        std::size_t pos = 0;
        if (after_cr_ && !piece.empty()) {
            after_cr_ = false;
            if (piece[0] == '\n') pos = 1;
        }
        while (pos < piece.size()) {
            const std::size_t end = piece.find_first_of("\r\n", pos);
            const std::size_t stop = end == std::string_view::npos ? piece.size() : end;
            if (pending_.size() + (stop - pos) > kMaxObjLineBytes)
                fail(name_, "", "line " + std::to_string(line_ + 1) + " is longer than " +
                                    std::to_string(kMaxObjLineBytes) + " bytes");
            if (end == std::string_view::npos) {
                pending_.append(piece.substr(pos));
                return;
            }
            ++line_;
            if (pending_.empty()) {
                statement(piece.substr(pos, end - pos));
            } else {
                pending_.append(piece.substr(pos, end - pos));
                statement(pending_);
                pending_.clear();
            }
            pos = end + 1;
            if (piece[end] == '\r') {
                if (pos == piece.size()) after_cr_ = true;
                else if (piece[pos] == '\n') ++pos;
            }
        }
    }

    MeshData finish() {
        if (!pending_.empty()) {
            ++line_;
            statement(pending_);
        }
        return mesh_.finish();
    }

private:
    const std::string& name_;
    mesh_io::MeshBuilder mesh_;
    std::string pending_;  // the start of a line that runs into the next piece
    bool after_cr_ = false;
    long line_ = 0;
    std::size_t faces_ = 0, texcoords_ = 0;
    // As read: floats (what the mesh keeps), so that a file of vertices costs 12 bytes each.
    std::vector<std::array<float, 3>> v_, vn_;
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_of_;  // (v, vn + 1) -> mesh vertex
    std::vector<std::uint32_t> corners_;

    std::string where() const { return "line " + std::to_string(line_); }

    void statement(std::string_view line) {
        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        Tokens t{line};
        std::string_view kw;
        if (!t.next(kw)) return;
        if (kw == "v") {
            if (v_.size() >= kMaxMeshVertices)
                fail(name_, where(), "more than " + std::to_string(kMaxMeshVertices) + " vertices, the limit");
            v_.push_back(numbers(t, 3, 7, "a vertex (v)"));  // x y z [w] or x y z r g b
        } else if (kw == "vn") {
            if (vn_.size() >= kMaxMeshVertices)
                fail(name_, where(), "more than " + std::to_string(kMaxMeshVertices) + " normals, the limit");
            vn_.push_back(numbers(t, 3, 3, "a normal (vn)"));
        } else if (kw == "vt") {
            ++texcoords_;
        } else if (kw == "f") {
            face(t);
        }
        // Everything else (o, g, s, mtllib, usemtl, p, l, free-form geometry) is skipped.
    }

    std::array<float, 3> numbers(Tokens& t, int least, int most, const char* what) {
        float x[3] = {0, 0, 0};
        int n = 0;
        for (std::string_view tok; t.next(tok); ++n) {
            float f;
            if (!mesh_io::parse_float(tok, f)) fail(name_, where(), mesh_io::not_a_number(tok));
            if (n < 3) x[n] = f;
        }
        if (n < least || n > most)
            fail(name_, where(), std::string(what) + " has " + std::to_string(n) + " numbers, not " +
                                     (least == most ? std::to_string(least)
                                                    : std::to_string(least) + " to " + std::to_string(most)));
        return {x[0], x[1], x[2]};
    }

    static Vec3 vec(const std::array<float, 3>& a) { return {a[0], a[1], a[2]}; }

    // An index of a corner: from 1, or negative from the end of what has been read so far.
    std::size_t index(std::string_view tok, std::size_t count, const char* what, const char* whats) {
        std::int64_t k = 0;
        if (!mesh_io::parse_int(tok, k) || k == 0)
            fail(name_, where(), "face " + std::to_string(faces_) + ": " + quoted(tok) +
                                     " is not a " + what + " index (1, 2, ... or -1, -2, ...)");
        const std::int64_t n = static_cast<std::int64_t>(count);
        if (k > n || k < -n)
            fail(name_, where(), "face " + std::to_string(faces_) + " refers to " + what + " " +
                                     std::to_string(k) + ", but " + std::to_string(count) + " " +
                                     (count == 1 ? what : whats) + (count == 1 ? " comes" : " come") +
                                     " before it");
        return static_cast<std::size_t>(k > 0 ? k - 1 : n + k);
    }

    void face(Tokens& t) {
        ++faces_;
        corners_.clear();
        for (std::string_view tok; t.next(tok);) {
            const std::size_t s1 = tok.find('/');
            const std::size_t s2 = s1 == std::string_view::npos ? s1 : tok.find('/', s1 + 1);
            const std::size_t v = index(tok.substr(0, s1), v_.size(), "vertex", "vertices");
            if (s1 != std::string_view::npos) {
                const std::string_view vt = tok.substr(s1 + 1, s2 == std::string_view::npos ? s2 : s2 - s1 - 1);
                if (!vt.empty()) index(vt, texcoords_, "texture coordinate", "texture coordinates");
            }
            std::size_t vn = 0;  // 0: none, else index + 1
            if (s2 != std::string_view::npos) vn = index(tok.substr(s2 + 1), vn_.size(), "normal", "normals") + 1;
            const std::uint64_t key = (std::uint64_t{v} << 32) | vn;
            auto [it, fresh] = vertex_of_.try_emplace(key, 0);
            if (fresh) it->second = mesh_.add_vertex(vec(v_[v]), vn ? vec(vn_[vn - 1]) : Vec3{});
            corners_.push_back(it->second);
        }
        mesh_.add_face(corners_, faces_);
    }
};

}  // namespace

MeshData parse_obj_pieces(const std::function<std::string_view()>& next_piece, const std::string& name) {
    ObjReader r(name);
    for (std::string_view piece = next_piece(); !piece.empty(); piece = next_piece()) r.feed(piece);
    return r.finish();
}

MeshData parse_obj(std::string_view text, const std::string& name) {
    ObjReader r(name);
    r.feed(text);
    return r.finish();
}

}  // namespace lat
