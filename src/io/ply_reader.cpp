// PLY (ASCII, binary little- and big-endian): the header is read whole and checked before any
// of the body. Nothing is allocated for what the header or a list claims: vertices and faces
// are stored as they are read, and a list's count is compared with the bytes that remain
// before its items are read, so memory and time follow what the file really holds, and a file
// that ends early says where.
//
// The header: "ply", one format line, comments, elements with their properties, "end_header",
// lines ending in LF or CR LF, printable text only, at most kMaxHeaderBytes. The mesh is the
// element "vertex" (scalar x, y, z; nx, ny, nz all three or none) and the element "face" (a list
// "vertex_indices" or "vertex_index" of integers), the vertices first; other elements and
// properties are read past (and checked as numbers of their type in ASCII).
#include <bit>
#include <cmath>
#include <limits>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_builder.h"
#include "io/mesh_file.h"
#include "util/error.h"

namespace lat {
namespace {

using mesh_io::fail;

constexpr std::size_t kMaxHeaderBytes = 65536;

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct TypeInfo {
    const char* name;
    const char* alias;
    std::size_t bytes;
    bool integral;
    double lo, hi;  // range of an integral type
};

constexpr TypeInfo kTypes[] = {
    {"char", "int8", 1, true, -128.0, 127.0},
    {"uchar", "uint8", 1, true, 0.0, 255.0},
    {"short", "int16", 2, true, -32768.0, 32767.0},
    {"ushort", "uint16", 2, true, 0.0, 65535.0},
    {"int", "int32", 4, true, -2147483648.0, 2147483647.0},
    {"uint", "uint32", 4, true, 0.0, 4294967295.0},
    {"float", "float32", 4, false, 0, 0},
    {"double", "float64", 8, false, 0, 0},
};

const TypeInfo& info(Type t) { return kTypes[static_cast<int>(t)]; }

bool type_named(std::string_view word, Type& t) {
    for (int k = 0; k < 8; ++k)
        if (word == kTypes[k].name || word == kTypes[k].alias) {
            t = static_cast<Type>(k);
            return true;
        }
    return false;
}

struct Property {
    std::string name;
    Type type = Type::kFloat32;  // of the value, or of a list's items
    bool list = false;
    Type count_type = Type::kUint8;
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> props;
    int find(std::string_view prop) const {
        for (std::size_t k = 0; k < props.size(); ++k)
            if (props[k].name == prop) return static_cast<int>(k);
        return -1;
    }
};

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        std::size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
        if (j > i) out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

class PlyReader {
public:
    PlyReader(std::string_view bytes, const std::string& name)
        : bytes_(bytes), name_(name), mesh_(name, [this] { return place(); }) {}

    MeshData read() {
        read_header();
        check_layout();
        if (ascii_) ++line_;  // the body starts on the line after end_header
        for (const Element& e : elements_) {
            if (&e == vertex_) {
                read_vertices(e);
            } else if (&e == face_) {
                read_faces(e);
            } else {
                for (std::uint64_t i = 0; i < e.count && !e.props.empty(); ++i)
                    if (!skip_element(e, i)) ends(e, i);
            }
        }
        return mesh_.finish();
    }

private:
    std::string_view bytes_;
    const std::string& name_;
    mesh_io::MeshBuilder mesh_;
    bool ascii_ = false, big_endian_ = false;
    std::vector<Element> elements_;
    const Element* vertex_ = nullptr;
    const Element* face_ = nullptr;
    std::size_t pos_ = 0;
    long line_ = 0;  // ASCII: the line of the last token read
    std::vector<std::uint32_t> corners_;

    std::string place() const { return ascii_ ? "line " + std::to_string(line_) : ""; }
    std::string at_line(long n) const { return "line " + std::to_string(n); }

    // ---- header --------------------------------------------------------------------------
    void read_header() {
        const std::size_t limit = std::min(bytes_.size(), kMaxHeaderBytes);
        bool format = false;
        for (;;) {
            const std::size_t nl = bytes_.substr(0, limit).find('\n', pos_);
            if (nl == std::string_view::npos) {
                if (bytes_.substr(0, limit).find('\r') != std::string_view::npos &&
                    bytes_.substr(0, limit).find('\n') == std::string_view::npos)
                    fail(name_, "", "the PLY header's lines end in CR alone; they must end in LF or CR LF");
                fail(name_, "", limit == kMaxHeaderBytes
                                    ? "no end_header line in the first " + std::to_string(kMaxHeaderBytes) +
                                          " bytes of the PLY header"
                                    : "the file ends in the PLY header, before its end_header line");
            }
            std::string_view line = bytes_.substr(pos_, nl - pos_);
            pos_ = nl + 1;
            ++line_;
            if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
            for (const char c : line)
                if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
                    fail(name_, at_line(line_), "the PLY header holds the byte " + printable({&c, 1}) +
                                                    ", which is not text");
            if (line_ == 1) {
                if (line != "ply")
                    fail(name_, "line 1", quoted(line) + " where a PLY file starts with 'ply'");
                continue;
            }
            const std::vector<std::string_view> w = words(line);
            if (w.empty()) continue;
            if (w[0] == "end_header" && w.size() == 1) break;
            if (w[0] == "comment" || w[0] == "obj_info") continue;
            if (w[0] == "format") {
                if (format) fail(name_, at_line(line_), "a second format line");
                format = true;
                read_format(w);
            } else if (w[0] == "element") {
                read_element(w);
            } else if (w[0] == "property") {
                read_property(w);
            } else {
                fail(name_, at_line(line_), quoted(w[0]) + " is not a PLY header keyword");
            }
        }
        if (!format) fail(name_, "", "the PLY header has no format line");
    }

    void read_format(const std::vector<std::string_view>& w) {
        if (w.size() != 3 || w[2] != "1.0")
            fail(name_, at_line(line_), "the format line must be 'format <ascii|binary_little_endian|"
                                        "binary_big_endian> 1.0'");
        if (w[1] == "ascii") {
            ascii_ = true;
        } else if (w[1] == "binary_big_endian") {
            big_endian_ = true;
        } else if (w[1] != "binary_little_endian") {
            fail(name_, at_line(line_), quoted(w[1]) + " is not a PLY format");
        }
    }

    void read_element(const std::vector<std::string_view>& w) {
        std::int64_t count = 0;
        if (w.size() != 3 || !mesh_io::parse_int(w[2], count) || count < 0)
            fail(name_, at_line(line_), "an element line must be 'element <name> <count>'");
        for (const Element& e : elements_)
            if (e.name == w[1])
                fail(name_, at_line(line_), "a second element " + quoted(w[1]));
        elements_.push_back({std::string(w[1]), static_cast<std::uint64_t>(count), {}});
    }

    void read_property(const std::vector<std::string_view>& w) {
        if (elements_.empty()) fail(name_, at_line(line_), "a property before any element");
        Property p;
        const bool list = w.size() == 5 && w[1] == "list";
        if (list) {
            p.list = true;
            if (!type_named(w[2], p.count_type) || !type_named(w[3], p.type))
                fail(name_, at_line(line_), "unknown type in a list property");
            if (!info(p.count_type).integral)
                fail(name_, at_line(line_), "the count of a list must have an integer type");
        } else if (w.size() != 3 || !type_named(w[1], p.type)) {
            fail(name_, at_line(line_), "a property line must be 'property <type> <name>' or "
                                        "'property list <count type> <item type> <name>'");
        }
        p.name = std::string(w.back());
        Element& e = elements_.back();
        if (e.find(p.name) >= 0)
            fail(name_, at_line(line_), "element " + quoted(e.name) + " has a second property " +
                                            quoted(p.name));
        e.props.push_back(std::move(p));
    }

    // The mesh's elements, and the counts against the bytes of the body.
    void check_layout() {
        for (const Element& e : elements_) {
            if (e.name == "vertex") vertex_ = &e;
            if (e.name == "face") face_ = &e;
        }
        if (!vertex_ || !face_)
            fail(name_, "", std::string("the mesh has no triangles: the PLY header has no '") +
                                (vertex_ ? "face" : "vertex") + "' element");
        if (face_ < vertex_) fail(name_, "", "the PLY header puts the faces before the vertices");
        for (const char* axis : {"x", "y", "z"})
            if (vertex_->find(axis) < 0 || vertex_->props[vertex_->find(axis)].list)
                fail(name_, "", std::string("the PLY vertices have no property '") + axis + "'");
        const int normals = (vertex_->find("nx") >= 0) + (vertex_->find("ny") >= 0) + (vertex_->find("nz") >= 0);
        if (normals != 0 && normals != 3)
            fail(name_, "", "the PLY vertices have some of nx, ny, nz but not all three");
        const int list = index_list();
        if (list < 0)
            fail(name_, "", "the PLY faces have no list property 'vertex_indices' (or 'vertex_index')");
        if (!info(face_->props[list].type).integral)
            fail(name_, "", "the PLY faces' vertex indices must have an integer type");
        if (vertex_->count > kMaxMeshVertices)
            fail(name_, "", std::to_string(vertex_->count) + " vertices is over the limit of " +
                                std::to_string(kMaxMeshVertices));
    }

    int index_list() const {
        for (const char* n : {"vertex_indices", "vertex_index"})
            if (const int k = face_->find(n); k >= 0 && face_->props[k].list) return k;
        return -1;
    }

    // ---- body ----------------------------------------------------------------------------
    [[noreturn]] void ends(const Element& e, std::uint64_t done, const std::string& why = "") const {
        const std::string what = &e == vertex_ ? "vertices" : &e == face_ ? "faces" : quoted(e.name) + " elements";
        fail(name_, "", "the file ends after " + std::to_string(done) + " of " + std::to_string(e.count) + " " +
                            what + (why.empty() ? "" : ": " + why));
    }

    // The next ASCII token, counting lines; empty at the end of the file.
    std::string_view token() {
        while (pos_ < bytes_.size()) {
            const char c = bytes_[pos_];
            if (c == '\n') ++line_;
            if (c != ' ' && c != '\t' && c != '\n' && c != '\r') break;
            ++pos_;
        }
        const std::size_t start = pos_;
        while (pos_ < bytes_.size() && bytes_[pos_] != ' ' && bytes_[pos_] != '\t' &&
               bytes_[pos_] != '\n' && bytes_[pos_] != '\r')
            ++pos_;
        return bytes_.substr(start, pos_ - start);
    }

    // One value of type t; false at the end of the file. ASCII values must be numbers of their
    // type (an integer in range, or a finite real).
    bool value(Type t, double& out) {
        const TypeInfo& ti = info(t);
        if (ascii_) {
            const std::string_view tok = token();
            if (tok.empty()) return false;
            if (ti.integral) {
                std::int64_t k = 0;
                if (!mesh_io::parse_int(tok, k) || static_cast<double>(k) < ti.lo || static_cast<double>(k) > ti.hi)
                    fail(name_, place(), quoted(tok) + " is not a number of type " + ti.name);
                out = static_cast<double>(k);
            } else if (t == Type::kFloat32) {
                float f = 0;
                if (!mesh_io::parse_float(tok, f)) fail(name_, place(), mesh_io::not_a_number(tok));
                out = f;
            } else if (!mesh_io::parse_double(tok, out)) {
                fail(name_, place(), mesh_io::not_a_number(tok));
            }
            return true;
        }
        if (bytes_.size() - pos_ < ti.bytes) return false;
        unsigned char b[8];
        std::memcpy(b, bytes_.data() + pos_, ti.bytes);
        pos_ += ti.bytes;
        if (big_endian_ != (std::endian::native == std::endian::big))
            for (std::size_t i = 0; i < ti.bytes / 2; ++i) std::swap(b[i], b[ti.bytes - 1 - i]);
        out = decode(t, b);
        return true;
    }

    static double decode(Type t, const unsigned char* b) {
        auto as = [b]<class T>(T) {
            T v;
            std::memcpy(&v, b, sizeof v);
            return static_cast<double>(v);
        };
        switch (t) {
            case Type::kInt8: return as(std::int8_t{});
            case Type::kUint8: return as(std::uint8_t{});
            case Type::kInt16: return as(std::int16_t{});
            case Type::kUint16: return as(std::uint16_t{});
            case Type::kInt32: return as(std::int32_t{});
            case Type::kUint32: return as(std::uint32_t{});
            case Type::kFloat32: return as(float{});
            case Type::kFloat64: return as(double{});
        }
        return 0;
    }

    // The count of list p of element `e`'s number i (from 0): a whole number, no more items
    // than the rest of the file can hold. False at the end of the file.
    bool list_count(const Property& p, const Element& e, std::uint64_t i, std::uint64_t& n) {
        double c = 0;
        if (!value(p.count_type, c)) return false;
        // ASCII items take a digit and a space each (the last one no space).
        const std::uint64_t rest = bytes_.size() - pos_;
        const std::uint64_t room = ascii_ ? (rest + 1) / 2 : rest / info(p.type).bytes;
        const std::string claim = element_name(e) + " " + std::to_string(i + 1) + " lists " +
                                  std::to_string(static_cast<long long>(c)) + " " + printable(p.name);
        if (c < 0) fail(name_, place(), claim);
        if (c > static_cast<double>(room)) ends(e, i, claim + ", more than the rest of the file holds");
        n = static_cast<std::uint64_t>(c);
        return true;
    }

    std::string element_name(const Element& e) const {
        return &e == vertex_ ? "vertex" : &e == face_ ? "face" : "element " + quoted(e.name);
    }

    // Reads one element past; false if the file ends within it.
    bool skip_element(const Element& e, std::uint64_t i) {
        double x = 0;
        for (const Property& p : e.props) {
            std::uint64_t n = 1;
            if (p.list && !list_count(p, e, i, n)) return false;
            if (!ascii_) {
                if (bytes_.size() - pos_ < n * info(p.type).bytes) return false;  // n: list_count
                pos_ += n * info(p.type).bytes;
                continue;
            }
            for (std::uint64_t k = 0; k < n; ++k)
                if (!value(p.type, x)) return false;
        }
        return true;
    }

    void read_vertices(const Element& e) {
        const int ix = e.find("x"), iy = e.find("y"), iz = e.find("z");
        const int inx = e.find("nx"), iny = e.find("ny"), inz = e.find("nz");
        std::vector<double> v(e.props.size(), 0.0);
        for (std::uint64_t i = 0; i < e.count; ++i) {
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                if (p.list) {
                    std::uint64_t n = 0;
                    double unused = 0;
                    if (!list_count(p, e, i, n)) ends(e, i);
                    for (std::uint64_t j = 0; j < n; ++j)
                        if (!value(p.type, unused)) ends(e, i);
                } else if (!value(p.type, v[k])) {
                    ends(e, i);
                }
            }
            // Rounded to float whatever the property's type, as OBJ vertices are: products of
            // coordinates (cross products, determinants) then stay far from overflowing.
            // Beyond the float range counts as not finite (the cast itself would be undefined).
            auto f = [&](int k) {
                const double x = v[k];
                return std::abs(x) <= static_cast<double>(std::numeric_limits<float>::max())
                           ? static_cast<double>(static_cast<float>(x))
                           : std::numeric_limits<double>::infinity();
            };
            const Vec3 pos{f(ix), f(iy), f(iz)};
            const Vec3 n = inx >= 0 ? Vec3{f(inx), f(iny), f(inz)} : Vec3{};
            if (!is_finite(pos) || !is_finite(n))
                fail(name_, place(), "vertex " + std::to_string(i + 1) + " is not finite (NaN or infinite)");
            mesh_.add_vertex(pos, n);
        }
    }

    void read_faces(const Element& e) {
        const int list = index_list();
        double x = 0;
        for (std::uint64_t i = 0; i < e.count; ++i) {
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                std::uint64_t n = 1;
                if (p.list && !list_count(p, e, i, n)) ends(e, i);
                if (static_cast<int>(k) != list) {
                    for (std::uint64_t j = 0; j < n; ++j)
                        if (!value(p.type, x)) ends(e, i);
                    continue;
                }
                corners_.clear();
                for (std::uint64_t j = 0; j < n; ++j) {
                    if (!value(p.type, x)) ends(e, i);
                    if (x < 0 || x >= static_cast<double>(vertex_->count))
                        fail(name_, place(), "face " + std::to_string(i + 1) + " refers to vertex " +
                                                 std::to_string(static_cast<long long>(x)) + ", but " +
                                                 (vertex_->count == 0 ? std::string("the file has no vertices")
                                                                      : "the file's vertices are 0 to " +
                                                                            std::to_string(vertex_->count - 1)));
                    corners_.push_back(static_cast<std::uint32_t>(x));
                }
            }
            mesh_.add_face(corners_, i + 1);
        }
    }
};

}  // namespace

MeshData parse_ply(std::string_view bytes, const std::string& name) {
    return PlyReader(bytes, name).read();
}

}  // namespace lat
