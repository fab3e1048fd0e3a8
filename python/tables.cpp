// lattice.open_table, lattice.rasterize and lattice.Table: a table's header, its lookups over
// numpy arrays of boundary point ids, its pairs, and its certification.
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <pybind11/stl.h>
#include <set>

#include "bindings.h"
#include "options.h"
#include "lattice/boundary_grid.h"
#include "lattice/cache/table_build.h"
#include "lattice/cache/table_cache.h"
#include "lattice/certify.h"
#include "lattice/table_file.h"
#include "render/render_request.h"
#include "scene/scene_loader.h"
#include "scene/table_metadata.h"
#include "scene_object.h"
#include "util/error.h"
#include "util/threads.h"

namespace lat::py {
namespace {

// The most pairs pairs() hands out: two uint32 arrays of 2 GB together.
constexpr std::uint64_t kMaxPairsListed = std::uint64_t{1} << 28;

struct PyTable {
    std::string path;
    TableHeader header;
    Primitive primitive;  // from the file's metadata; the table's exact lookups use its shape
    LoadedTable loaded;
    BoundaryGrid grid{{1, 1, 1}};
};

std::shared_ptr<PyTable> open_table(const std::string& path) {
    auto t = std::make_shared<PyTable>();
    t->path = path;
    t->header = read_table_header(path);
    t->primitive = primitive_from_metadata(t->header, path);
    t->loaded = load_table_file(path, nullptr, t->primitive.shape.get());
    t->grid = BoundaryGrid(t->header.cells);
    return t;
}

using IdArray = pyb::array_t<std::uint32_t, pyb::array::c_style | pyb::array::forcecast>;

// Ids as uint32, each checked to be a boundary point: "entry[5]: 4000 is not ...".
IdArray checked_ids(const pyb::array& ids, const char* what, const BoundaryGrid& grid) {
    if (!pyb::isinstance<pyb::array_t<std::int64_t>>(ids) && !pyb::isinstance<pyb::array_t<std::uint32_t>>(ids) &&
        !pyb::isinstance<pyb::array_t<std::int32_t>>(ids) && !pyb::isinstance<pyb::array_t<std::uint64_t>>(ids))
        throw pyb::type_error(std::string(what) + ": expected an array of integers (boundary point ids)");
    const auto wide = pyb::array_t<std::int64_t, pyb::array::c_style | pyb::array::forcecast>::ensure(ids);
    const std::int64_t* v = wide.data();
    for (pyb::ssize_t i = 0; i < wide.size(); ++i)
        if (v[i] < 0 || v[i] >= grid.count())
            throw InputError(std::string(what) + "[" + std::to_string(i) + "]: " + std::to_string(v[i]) +
                             " is not a boundary point id (0 to " + std::to_string(grid.count() - 1) + ")");
    return IdArray::ensure(wide);
}

// lookup(entry, exit): every pair at once, in parallel, without the GIL.
pyb::dict lookup(const PyTable& t, const pyb::array& entry_ids, const pyb::array& exit_ids) {
    const IdArray a = checked_ids(entry_ids, "entry", t.grid);
    const IdArray b = checked_ids(exit_ids, "exit", t.grid);
    if (a.size() != b.size()) throw InputError("entry and exit differ in length");
    const std::size_t n = static_cast<std::size_t>(a.size());
    pyb::array_t<bool> hit(static_cast<pyb::ssize_t>(n));
    pyb::array_t<double> tt(static_cast<pyb::ssize_t>(n));
    pyb::array_t<double> point({static_cast<pyb::ssize_t>(n), pyb::ssize_t{3}});
    pyb::array_t<double> normal({static_cast<pyb::ssize_t>(n), pyb::ssize_t{3}});
    bool* h = hit.mutable_data();
    double *tv = tt.mutable_data(), *p = point.mutable_data(), *nv = normal.mutable_data();
    const std::uint32_t *ea = a.data(), *eb = b.data();
    {
        const pyb::gil_scoped_release release;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const GridPoint ga = t.grid.point(ea[i]), gb = t.grid.point(eb[i]);
                TableHit th;
                h[i] = ea[i] != eb[i] && BoundaryGrid::valid_pair(t.grid.faces(ga), t.grid.faces(gb)) &&
                       t.loaded.table->lookup(ea[i], eb[i], th);
                const double nan = std::numeric_limits<double>::quiet_NaN();
                const Vec3 at = h[i] ? to_vec(ga) + th.t * (to_vec(gb) - to_vec(ga)) : Vec3{nan, nan, nan};
                const Vec3 nn = h[i] ? th.normal : Vec3{nan, nan, nan};
                tv[i] = h[i] ? th.t : nan;
                for (int c = 0; c < 3; ++c) {
                    p[3 * i + c] = at[c];
                    nv[3 * i + c] = nn[c];
                }
            }
        });
    }
    pyb::dict d;
    d["hit"] = hit;
    d["t"] = tt;
    d["point"] = point;
    d["normal"] = normal;
    return d;
}

pyb::array_t<std::int32_t> points(const PyTable& t) {
    pyb::array_t<std::int32_t> out({static_cast<pyb::ssize_t>(t.grid.count()), pyb::ssize_t{3}});
    std::int32_t* o = out.mutable_data();
    for (std::uint32_t id = 0; id < t.grid.count(); ++id) {
        const GridPoint g = t.grid.point(id);
        o[3 * id] = g.x;
        o[3 * id + 1] = g.y;
        o[3 * id + 2] = g.z;
    }
    return out;
}

// Every valid ordered pair (two points, not both on one face), entry ids ascending: the pairs
// `lattice inspect` certifies.
pyb::tuple pairs(const PyTable& t) {
    const std::uint32_t n = t.grid.count();
    std::vector<std::uint8_t> faces(n);
    for (std::uint32_t id = 0; id < n; ++id) faces[id] = t.grid.faces(t.grid.point(id));
    std::uint64_t count = 0;
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j = 0; j < n; ++j) count += j != i && BoundaryGrid::valid_pair(faces[i], faces[j]);
    if (count > kMaxPairsListed)
        throw InputError(t.path + ": " + std::to_string(count) + " pairs are more than pairs() lists (" +
                         std::to_string(kMaxPairsListed) + "); sample ids from points() instead");
    pyb::array_t<std::uint32_t> a(static_cast<pyb::ssize_t>(count)), b(static_cast<pyb::ssize_t>(count));
    std::uint32_t *pa = a.mutable_data(), *pb = b.mutable_data();
    std::uint64_t k = 0;
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j = 0; j < n; ++j)
            if (j != i && BoundaryGrid::valid_pair(faces[i], faces[j])) {
                pa[k] = i;
                pb[k++] = j;
            }
    return pyb::make_tuple(a, b);
}

pyb::dict certify(const PyTable& t, int threads) {
    if (const double n = static_cast<double>(BoundaryGrid::pair_count(t.header.cells)); n > kMaxCertifyPairs)
        throw InputError(t.path + ": certifying would re-intersect " + std::to_string(n) +
                         " point pairs, more than the limit");
    CertifyReport r;
    {
        const pyb::gil_scoped_release release;
        const std::lock_guard lock(process_mutex());
        const ThreadLimit limit(threads);
        r = certify_table(*t.loaded.table, t.header.context(t.primitive.shape.get()), false);
    }
    pyb::dict d;
    d["pairs"] = r.pairs;
    d["exact_hits"] = r.exact_hits;
    d["false_hits"] = r.false_hits;
    d["false_misses"] = r.false_misses;
    d["max_point_error_sigma"] = r.max_point_error;
    d["mean_point_error_sigma"] = r.mean_point_error;
    d["max_normal_error_deg"] = r.max_normal_error_deg;
    d["mean_normal_error_deg"] = r.mean_normal_error_deg;
    d["seconds"] = r.seconds;
    return d;
}

// The table options (--sigma-inv, --encoding, ...) from keywords, as render() reads them.
TableSpec table_spec(const pyb::kwargs& kw) {
    TableSpec spec;
    for (const auto& [key, value] : kw) {
        const std::string name = key.cast<std::string>();
        const OptionEntry<TableSpec>* entry = nullptr;
        for (const OptionEntry<TableSpec>& e : table_option_entries())
            if (e.python_name() == name) entry = &e;
        if (!entry) throw pyb::type_error("rasterize() got an unexpected option '" + name + "'");
        if (value.is_none()) continue;
        set_option(spec, *entry, value);
    }
    return spec;
}

std::shared_ptr<PyTable> rasterize(const PyScene& s, const std::string& primitive, std::optional<std::string> output,
                                   std::optional<std::string> lattice_dir, int threads, const pyb::kwargs& kw) {
    const TablePlan plan = plan_table(find_primitive(s.scene, primitive), table_spec(kw), s.scene.file);
    std::string path = output.value_or("");
    if (path.empty()) {
        const std::string dir = lattice_dir.value_or("");
        const TableCache cache(dir.empty() ? default_cache_dir() : dir, !dir.empty());
        path = cache.path_for(plan);
    }
    {
        const pyb::gil_scoped_release release;
        const std::lock_guard lock(process_mutex());
        const ThreadLimit limit(threads);
        build_table_file(plan, path, false);
    }
    return open_table(path);
}

void bind_table_class(pyb::module_& m) {
    pyb::class_<PyTable, std::shared_ptr<PyTable>>(m, "Table", R"(A lattice table file (.lht), opened.

Boundary points are the lattice box's grid points on its faces, by id (points() gives their
coordinates in lattice units, cells at the refinement); a pair (entry, exit) of ids on
different faces stands for the segment between them, and the table holds its hit closest to
the entry point, if any.)")
        .def_property_readonly("path", [](const PyTable& t) { return t.path; })
        .def_property_readonly("encoding", [](const PyTable& t) { return t.header.encoding; })
        .def_property_readonly("cells", [](const PyTable& t) { return t.header.cells; })
        .def_property_readonly("sigma", [](const PyTable& t) { return t.header.sigma; })
        .def_property_readonly("sigma_inv", [](const PyTable& t) { return t.header.sigma_inv; })
        .def_property_readonly("cell", [](const PyTable& t) { return t.header.cell; })
        .def_property_readonly("n_lp", [](const PyTable& t) { return t.header.pairs; }, "N_lp, eq. (2)")
        .def_property_readonly("stored_hits", [](const PyTable& t) { return t.header.entries; })
        .def_property_readonly("bytes", [](const PyTable& t) { return t.loaded.bytes; })
        .def_property_readonly("primitive", [](const PyTable& t) { return t.primitive.name; })
        .def_property_readonly("metadata", [](const PyTable& t) {
            return pyb::module_::import("json").attr("loads")(t.header.metadata);
        })
        .def_property_readonly("details", [](const PyTable& t) { return t.loaded.table->details(); })
        .def_property_readonly("point_count", [](const PyTable& t) { return t.grid.count(); })
        .def("points", &points, "Every boundary point's grid coordinates, by id: (N, 3) int32")
        .def("pairs", &pairs, "Every valid ordered pair as two uint32 arrays (entry, exit)")
        .def("lookup", &lookup, pyb::arg("entry"), pyb::arg("exit"),
             R"(Looks up many pairs at once (arrays of ids, same length).

Returns a dict of arrays: hit (bool), t (the hit at entry + t (exit - entry)), point (N x 3,
lattice units) and normal (N x 3, unit, outward); NaN where there is no hit. Pairs on one
face, and a point with itself, are misses. Ids that are not boundary points raise InputError.)")
        .def("certify", &certify, pyb::arg("threads") = 0,
             "Every pair against exact intersection, as `lattice inspect` certifies: a dict")
        .def("__repr__", [](const PyTable& t) { return "<lattice.Table " + t.path + ": " + t.header.describe() + ">"; });
}

}  // namespace

void bind_tables(pyb::module_& m) {
    bind_table_class(m);
    m.def("open_table", &open_table, pyb::arg("path"), "Opens and checks a table file; InputError if it is not one");
    m.def("rasterize", &rasterize, pyb::arg("scene"), pyb::arg("primitive"), pyb::kw_only(),
          pyb::arg("output") = pyb::none(), pyb::arg("lattice_dir") = pyb::none(), pyb::arg("threads") = 0,
          R"(Rasterizes a primitive of the scene into a table, as `lattice rasterize` does, and opens it.

Table options as keywords: sigma_inv, encoding, max_point_error, max_normal_error,
dense_normals. output: the file (default: the render cache, where render finds it).)");
}

}  // namespace lat::py
