#include "scene/lattice_tables.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "csg/csg_shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/lattice_shape.h"
#include "scene/object_parser.h"
#include "scene/scene_loader.h"
#include "util/error.h"
#include "util/hash.h"
#include "util/memory.h"

namespace lat {
namespace {

constexpr int kMaxSigmaInv = 1 << 20;

std::string where(const Primitive& p, const std::string& file) {
    return located_message(file, p.where, "");
}

LatticeGrid grid_of(const TableHeader& h) {
    return {h.cells, h.cell};
}

}  // namespace

TableHeader lattice_header(const Primitive& p, const TableSpec& spec,
                           const std::string& scene_file) {
    const int sigma_inv = spec.sigma_inv;
    if (!p.lattice)
        throw InputError(where(p, scene_file) + "primitive '" + p.name +
                         "' has no lattice (add \"lattice\": {\"sigma\": ..., \"cells\": [...]})");
    if (sigma_inv < 1 || sigma_inv > kMaxSigmaInv)
        throw InputError("--sigma-inv " + std::to_string(sigma_inv) + ": must be between 1 and " +
                         std::to_string(kMaxSigmaInv));
    TableHeader h;
    h.encoding = encoding_info(spec.encoding).name;
    h.sigma = p.lattice->sigma;
    h.sigma_inv = sigma_inv;
    h.cell = p.lattice->sigma / sigma_inv;
    for (std::size_t a = 0; a < 3; ++a) {
        const long long n = static_cast<long long>(p.lattice->cells[a]) * sigma_inv;
        h.cells[a] = static_cast<int>(std::min<long long>(n, 0x7FFFFFFF));
    }
    h.fingerprint = Fingerprint()
                        .add(p.fingerprint)
                        .add(h.sigma)
                        .add(h.cells[0])
                        .add(h.cells[1])
                        .add(h.cells[2])
                        .add(sigma_inv)
                        .add(h.encoding)
                        .add(spec.options.max_point_error)
                        .add(spec.options.max_normal_error_deg)
                        .add(spec.options.normals)
                        .add(kRasterizerVersion)
                        .value();
    h.metadata = nlohmann::json{
        {"primitive", p.name},
        {"definition", nlohmann::json::parse(p.definition)},
        {"scene",
         scene_file}}.dump();
    return h;
}

TableContext table_context(const Primitive& p, const TableHeader& h) {
    return {h.cells, h.cell, h.sigma, p.shape.get()};
}

void check_table_buildable(const Primitive& p, const TableSpec& spec,
                           const std::string& scene_file) {
    const TableHeader h = lattice_header(p, spec, scene_file);
    const int sigma_inv = spec.sigma_inv;
    const std::string& encoding = spec.encoding;
    const std::string at = where(p, scene_file);
    // The primitive must lie in its box: the table cannot see what sticks out.
    const Bounds3 b = p.shape->bounds();
    const double X = p.lattice->cells[0] * p.lattice->sigma,
                 Y = p.lattice->cells[1] * p.lattice->sigma,
                 Z = p.lattice->cells[2] * p.lattice->sigma;
    const double tol = 1e-9 * std::max({X, Y, Z});
    if (!b.finite() || b.lo.x < -tol || b.lo.y < -tol || b.lo.z < -tol || b.hi.x > X + tol ||
        b.hi.y > Y + tol || b.hi.z > Z + tol) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "primitive '%s' reaches outside its lattice box [0, %g] x [0, %g] x [0, %g] "
                      "(its bounds are [%g, %g] x [%g, %g] x [%g, %g])",
                      p.name.c_str(), X, Y, Z, b.lo.x, b.hi.x, b.lo.y, b.hi.y, b.lo.z, b.hi.z);
        throw InputError(at + buf);
    }
    // Sizes, in floating point so that absurd refinements cannot overflow.
    const long double nx = h.cells[0], ny = h.cells[1], nz = h.cells[2];
    const long double yz = (ny + 1) * (nz + 1), zx = (nz + 1) * (nx + 1), xy = (nx + 1) * (ny + 1);
    const long double pairs = 8 * (xy * yz + yz * zx + zx * xy) + 2 * (xy * xy + yz * yz + zx * zx);
    const long double points = 2 * (xy + yz + zx);  // an upper bound (edges counted twice)
    const EncodingInfo& enc = encoding_info(encoding);
    const std::string size = std::to_string(h.cells[0]) + " x " + std::to_string(h.cells[1]) +
                             " x " + std::to_string(h.cells[2]) +
                             " cells (sigma^-1 = " + std::to_string(sigma_inv) + ")";
    const double avail = static_cast<double>(available_memory_bytes());
    auto refuse = [&](double hit_rate, double bytes, bool lower_bound) {
        char buf[512];
        std::snprintf(buf, sizeof buf,
                      "the %s table of primitive '%s' at %s would need %s %s (%.3Lg point pairs, "
                      "%s %.0f %% of them %s, at %.1f bytes per hit while building), more than the "
                      "%s of memory available",
                      encoding.c_str(), p.name.c_str(), size.c_str(),
                      lower_bound ? "at least" : "about", human_bytes(bytes).c_str(), pairs,
                      lower_bound ? "even if only" : "an estimated", hit_rate * 100,
                      lower_bound ? "were hits" : "hits", enc.bytes_per_hit + sizeof(RawHit),
                      human_bytes(avail).c_str());
        throw InputError(at + buf);
    };
    const double per_hit = enc.bytes_per_hit + sizeof(RawHit);
    // Even a 1 % hit rate is too much: refuse without tracing anything.
    if (avail > 0 && static_cast<double>(pairs) * 0.01 * per_hit > 0.8 * avail)
        refuse(0.01, static_cast<double>(pairs) * 0.01 * per_hit, true);
    if (points >= static_cast<long double>(0xFFFFFFFFu))
        throw InputError(at + "a lattice of " + size + " has too many boundary points to index");
    const BoundaryGrid grid(h.cells);
    if (grid.count() > enc.max_points)
        throw InputError(at + "the " + encoding + " encoding keys at most " +
                         std::to_string(enc.max_points) + " boundary points; a lattice of " + size +
                         " has " + std::to_string(grid.count()));
    // Estimate the hit rate by tracing every n-th entry point.
    RasterizeOptions opt;
    opt.keep_hits = false;
    opt.entry_stride = std::max<std::uint32_t>(1, grid.count() / 512);
    const RasterizeResult sample = rasterize(*p.shape, grid_of(h), opt);
    const double rate =
        sample.pairs_traced ? double(sample.hits) / double(sample.pairs_traced) : 0.0;
    const double need = static_cast<double>(pairs) * rate * per_hit;
    if (avail > 0 && need > 0.8 * avail) refuse(rate, need, false);
}

TableBuild build_table_file(const Primitive& p, const TableSpec& spec, const std::string& path,
                            const std::string& scene_file, bool progress) {
    check_table_buildable(p, spec, scene_file);
    TableBuild b;
    b.header = lattice_header(p, spec, scene_file);
    RasterizeOptions opt;
    opt.progress = progress;
    opt.keep_hits = encoding_info(spec.encoding).needs_hits;
    b.raster = rasterize(*p.shape, grid_of(b.header), opt);
    const auto t0 = std::chrono::steady_clock::now();
    const ByteBuffer payload =
        encode_table(spec.encoding, b.raster, table_context(p, b.header), spec.options);
    b.encode_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    b.raster.raw = {};
    b.header.pairs = b.raster.pairs_eq2;
    b.header.entries = b.raster.hits;
    write_table_file(path, b.header, payload);
    b.bytes = payload.size() + kTableHeaderBytes + b.header.metadata.size();
    return b;
}

Primitive primitive_from_metadata(const TableHeader& h, const std::string& path) {
    nlohmann::json meta;
    try {
        meta = nlohmann::json::parse(h.metadata);
    } catch (const nlohmann::json::exception&) {
        throw InputError(path + ": the table's metadata is not valid JSON");
    }
    if (!meta.is_object() || !meta.contains("definition") || !meta.contains("primitive"))
        throw InputError(path + ": the table's metadata does not describe its primitive");
    const std::string where = path + " (metadata)";
    const JsonValue def(meta["definition"], "definition", where);
    const std::map<std::string, std::uint32_t> no_materials;
    const std::vector<Primitive> no_primitives;
    const ObjectParser parser(no_materials, no_primitives);
    Primitive p = parse_primitive(def, meta["primitive"].get<std::string>(), &parser);
    p.lattice = LatticeSpec{
        h.sigma, {h.cells[0] / h.sigma_inv, h.cells[1] / h.sigma_inv, h.cells[2] / h.sigma_inv}};
    return p;
}

std::string default_cache_dir() {
    if (const char* d = std::getenv("LATTICE_CACHE_DIR"); d && *d) return d;
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/lattice";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::string(home) + "/.cache/lattice";
    return ".lattice-cache";
}

TableCache::TableCache(const std::string& dir, bool explicit_dir) : dir_(dir) {
    struct stat st {};
    if (::stat(dir_.c_str(), &st) != 0) {
        if (explicit_dir)
            throw InputError(dir_ +
                             ": lattice cache directory does not exist: " + std::strerror(errno));
        std::error_code ec;
        std::filesystem::create_directories(dir_, ec);
        if (ec)
            throw InputError(dir_ + ": cannot create the lattice cache directory: " + ec.message());
    } else if (!S_ISDIR(st.st_mode)) {
        throw InputError(dir_ + ": lattice cache is not a directory");
    }
    if (::access(dir_.c_str(), R_OK | W_OK | X_OK) != 0)
        throw InputError(dir_ + ": lattice cache directory is not readable and writable: " +
                         std::strerror(errno));
}

std::string TableCache::path_for(const Primitive& p, const TableSpec& spec,
                                 const std::string& scene_file) const {
    const TableHeader h = lattice_header(p, spec, scene_file);
    std::string safe;
    for (char c : p.name)
        safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    char tail[64];
    std::snprintf(tail, sizeof tail, "-s%d-%s-%016llx.lht", spec.sigma_inv, spec.encoding.c_str(),
                  static_cast<unsigned long long>(h.fingerprint));
    return dir_ + "/" + safe.substr(0, 64) + tail;
}

TableCache::Entry TableCache::get(const Primitive& p, const TableSpec& spec,
                                  const std::string& scene_file, bool progress) const {
    Entry e;
    e.path = path_for(p, spec, scene_file);
    const TableHeader expected = lattice_header(p, spec, scene_file);
    struct stat st {};
    if (::stat(e.path.c_str(), &st) != 0) {
        const auto t0 = std::chrono::steady_clock::now();
        build_table_file(p, spec, e.path, scene_file, progress);
        e.build_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        e.built = true;
    }
    try {
        LoadedTable lt = load_table_file(e.path, &expected, p.shape.get());
        e.table = lt.table;
        e.header = lt.header;
    } catch (const InputError& err) {
        throw InputError(std::string(err.what()) + " (delete the file to rebuild it)");
    }
    return e;
}

SceneLattices scene_lattices(const Scene& scene, const TableCache& cache, const TableSpec& spec,
                             bool progress) {
    SceneLattices out;
    out.shapes.resize(scene.primitives.size());
    // Instances, at the top level or as CSG leaves.
    std::vector<bool> used(scene.primitives.size(), false);
    for (const SceneObject& o : scene.objects) {
        if (o.primitive >= 0) used[static_cast<std::size_t>(o.primitive)] = true;
        if (const auto* csg = dynamic_cast<const CsgShape*>(o.shape.get()))
            for (const int p : csg->leaf_primitives()) used[static_cast<std::size_t>(p)] = true;
    }
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
        if (!used[i]) continue;
        const Primitive& p = scene.primitives[i];
        const TableCache::Entry e = cache.get(p, spec, scene.file, progress);
        const TableContext ctx{e.header.cells, e.header.cell, e.header.sigma, p.shape.get()};
        out.shapes[i] =
            std::make_shared<LatticeShape>(e.table, e.header.cells, e.header.cell, p.shape.get(),
                                           hit_error_bound(e.header.encoding, ctx, spec.options));
        out.table_bytes += e.table->bytes();
        out.table_entries += e.table->entries();
        out.built += e.built ? 1 : 0;
        out.build_seconds += e.build_seconds;
        out.paths.push_back(e.path);
    }
    return out;
}

}  // namespace lat
