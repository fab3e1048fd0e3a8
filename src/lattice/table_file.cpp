#include "lattice/table_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <map>
#include <stdexcept>
#include <vector>

#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
#include "util/atomic_file.h"
#include "util/big_buffer.h"
#include "util/error.h"
#include "util/file.h"
#include "util/hash.h"

namespace lat {
namespace {

constexpr char kMagic[8] = {'L', 'A', 'T', 'T', 'I', 'C', 'E', '\x1a'};

// Little-endian field writer/reader over the fixed header (x86-64 and ARM are little-endian;
// the static_assert below keeps it honest).
static_assert(std::endian::native == std::endian::little, "table files are little-endian");

struct Fields {
    std::uint8_t* p;
    std::size_t off = 0;
    template <class T>
    void put(const T& v) {
        std::memcpy(p + off, &v, sizeof v);
        off += sizeof v;
    }
};
struct Reader {
    const std::uint8_t* p;
    std::size_t off = 0;
    template <class T>
    T get() {
        T v;
        std::memcpy(&v, p + off, sizeof v);
        off += sizeof v;
        return v;
    }
};

std::array<std::uint8_t, kTableHeaderBytes> encode_header(const TableHeader& h,
                                                          std::uint64_t payload_checksum) {
    std::array<std::uint8_t, kTableHeaderBytes> b{};
    Fields f{b.data()};
    for (char c : kMagic) f.put(c);
    f.put(kTableFormatVersion);
    f.put(static_cast<std::uint32_t>(kTableHeaderBytes));
    char enc[16] = {};
    std::strncpy(enc, h.encoding.c_str(), sizeof enc - 1);
    for (char c : enc) f.put(c);
    for (int c : h.cells) f.put(static_cast<std::int32_t>(c));
    f.put(static_cast<std::int32_t>(h.sigma_inv));
    f.put(h.sigma);
    f.put(h.cell);
    f.put(h.fingerprint);
    f.put(h.pairs);
    f.put(h.entries);
    f.put(h.payload_bytes);
    f.put(static_cast<std::uint64_t>(h.metadata.size()));
    f.put(payload_checksum);
    const std::uint64_t header_checksum = hash_bytes(b.data(), f.off);
    f.put(header_checksum);
    return b;
}

// The lattice a header describes must be one this program could have written: numbers finite
// and in range, consistent with each other, and small enough to index. Empty when it is.
std::string lattice_error(const TableHeader& h) {
    if (std::string e = sigma_inv_error(h.sigma_inv); !e.empty()) return e;
    if (!(std::isnormal(h.sigma) && h.sigma > 0 && h.sigma < 1e300))
        return "sigma must be a positive finite number";
    if (!(std::isnormal(h.cell) && h.cell == h.sigma / h.sigma_inv))
        return "the cell size is not sigma / sigma^-1";
    for (const int c : h.cells)
        if (c < 1 || c % h.sigma_inv != 0)
            return "the cells must be positive multiples of sigma^-1";
    if (!BoundaryGrid::indexable(h.cells))
        return "the lattice has too many boundary points to index";
    if (BoundaryGrid::pair_count(h.cells) != static_cast<long double>(h.pairs))
        return "N_lp does not match the cells";
    if (h.entries > h.pairs) return "more stored hits than point pairs";
    return {};
}

TableHeader decode_header(const std::uint8_t* b, std::size_t file_size, const std::string& path,
                          std::uint64_t& payload_checksum, std::uint64_t& meta_bytes) {
    auto bad = [&](const std::string& what) -> InputError {
        return InputError(path + ": not a valid lattice table: " + what);
    };
    if (file_size < kTableHeaderBytes) throw bad("file is too short for a header (truncated?)");
    if (std::memcmp(b, kMagic, sizeof kMagic) != 0) throw bad("wrong magic number");
    Reader r{b, sizeof kMagic};
    const auto version = r.get<std::uint32_t>();
    if (version != kTableFormatVersion)
        throw InputError(path + ": lattice table format version " + std::to_string(version) +
                         ", this program reads version " + std::to_string(kTableFormatVersion) +
                         " (rebuild it with lattice rasterize)");
    if (r.get<std::uint32_t>() != kTableHeaderBytes) throw bad("unexpected header size");
    char enc[16];
    for (char& c : enc) c = r.get<char>();
    enc[15] = 0;
    TableHeader h;
    h.coverage_rays = kAnyCoverageRays;
    h.encoding = enc;
    for (int& c : h.cells) c = r.get<std::int32_t>();
    h.sigma_inv = r.get<std::int32_t>();
    h.sigma = r.get<double>();
    h.cell = r.get<double>();
    h.fingerprint = r.get<std::uint64_t>();
    h.pairs = r.get<std::uint64_t>();
    h.entries = r.get<std::uint64_t>();
    h.payload_bytes = r.get<std::uint64_t>();
    meta_bytes = r.get<std::uint64_t>();
    payload_checksum = r.get<std::uint64_t>();
    const std::size_t covered = r.off;
    if (r.get<std::uint64_t>() != hash_bytes(b, covered)) throw bad("header checksum mismatch (corrupt)");
    const std::uint64_t body = file_size - kTableHeaderBytes;
    if (h.payload_bytes > body || meta_bytes != body - h.payload_bytes)
        throw bad("file holds " + std::to_string(body) + " bytes after the header, header says " +
                  std::to_string(h.payload_bytes + meta_bytes) + " (truncated?)");
    if (const std::string e = lattice_error(h); !e.empty()) throw bad(e);
    return h;
}

// A whole file in memory, shared by the table made over it: mapped read-only, or for large
// tables read into anonymous memory with huge pages, since their lookups land at random over
// hundreds of megabytes, and with 4 kB pages of a mapped file nearly every one would also miss
// the TLB (Plate 4's filtered lattice, 350 MB of coverage tables: 13 % less render time).
struct Mapping {
    static constexpr std::size_t kCopyAbove = std::size_t{64} << 20;
    void* addr = nullptr;
    std::size_t size = 0;
    ByteBuffer copy;
    const std::uint8_t* bytes() const {
        return copy.size() ? copy.data() : static_cast<const std::uint8_t*>(addr);
    }
    ~Mapping() {
        if (addr && addr != MAP_FAILED) ::munmap(addr, size);
    }
};

// Reads the whole of fd into m.copy; false (errno set) on a read error or a short file.
bool read_whole(int fd, Mapping& m) {
    m.copy = ByteBuffer(m.size);
    for (std::size_t done = 0; done < m.size;) {
        const ssize_t n = ::pread(fd, m.copy.data() + done, m.size - done, static_cast<off_t>(done));
        if (n <= 0) {
            if (n < 0 && errno == EINTR) continue;
            if (n == 0) errno = EIO;
            return false;
        }
        done += static_cast<std::size_t>(n);
    }
    return true;
}

// Adds to h the n bytes `out` holds at `offset` (bytes never written read as zeros), mapped
// from the page cache, where they were just written.
void hash_written(const AtomicFile& out, std::size_t offset, std::size_t n, HashStream& h) {
    if (n == 0) return;
    const int fd = ::fileno(out.file());
    if (::ftruncate(fd, static_cast<off_t>(offset + n)) != 0)
        throw_write_errno(out.target(), errno, "lattice table");
    const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    const std::size_t start = offset / page * page;
    void* p = ::mmap(nullptr, offset + n - start, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(start));
    if (p == MAP_FAILED) throw_write_errno(out.target(), errno, "lattice table");
    h.add(static_cast<const std::uint8_t*>(p) + (offset - start), n);
    ::munmap(p, offset + n - start);
}

// Puts a payload's pieces into a table file, after its header, and hashes the pieces that come
// in order as they go by (from memory the encoder has just filled, still in cache); a piece a
// little ahead waits, copied, for the ones before it. What is not hashed so is read back from
// the file at the end (all of it if a piece rewrites bytes already hashed).
class FileSink final : public PayloadSink {
public:
    explicit FileSink(AtomicFile& out) : out_(out) {}
    void reserve(std::size_t size) override { size_ = size; }
    void write_at(std::size_t offset, const void* data, std::size_t n) override {
        assert(offset <= size_ && n <= size_ - offset);
        out_.write_at(kTableHeaderBytes + offset, data, n);
        if (!in_order_ || n == 0) return;
        if (offset < hashed_) {
            in_order_ = false, waiting_.clear();
            return;
        }
        // A waiting copy this piece overlaps is stale.
        const auto after = waiting_.lower_bound(offset + n);
        if (after != waiting_.begin() && std::prev(after)->first + std::prev(after)->second.size() > offset)
            waiting_.clear(), waiting_bytes_ = 0;
        const auto* bytes = static_cast<const std::uint8_t*>(data);
        if (offset == hashed_) {
            hash_.add(bytes, n);
            hashed_ += n;
            for (auto it = waiting_.begin(); it != waiting_.end() && it->first == hashed_; it = waiting_.erase(it)) {
                hash_.add(it->second.data(), it->second.size());
                hashed_ += it->second.size(), waiting_bytes_ -= it->second.size();
            }
        } else if (offset + n - hashed_ <= kAhead && waiting_bytes_ + n <= kAhead) {
            waiting_.emplace(offset, std::vector<std::uint8_t>(bytes, bytes + n));
            waiting_bytes_ += n;
        }
    }
    std::size_t size() const { return size_; }
    // hash_bytes of the whole payload.
    std::uint64_t checksum() {
        if (!in_order_) hash_ = HashStream(), hashed_ = 0;
        waiting_.clear(), waiting_bytes_ = 0;
        hash_written(out_, kTableHeaderBytes + hashed_, size_ - hashed_, hash_);
        hashed_ = size_;
        return hash_.value();
    }

private:
    static constexpr std::size_t kAhead = std::size_t{16} << 20;
    AtomicFile& out_;
    std::size_t size_ = 0;
    HashStream hash_;
    std::size_t hashed_ = 0;  // the payload's bytes [0, hashed_) are in hash_
    bool in_order_ = true;
    std::map<std::size_t, std::vector<std::uint8_t>> waiting_;  // by offset
    std::size_t waiting_bytes_ = 0;
};

}  // namespace

std::string TableHeader::describe() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s, %d x %d x %d cells (sigma %g, sigma^-1 %d)",
                  encoding.c_str(), cells[0], cells[1], cells[2], sigma, sigma_inv);
    return buf;
}

void write_table_file(const std::string& path, const TableHeader& h, const ByteBuffer& payload) {
    write_table_file(path, h, [&](PayloadSink& sink) {
        sink.reserve(payload.size());
        sink.write_at(0, payload.data(), payload.size());
    });
}

std::uint64_t write_table_file(const std::string& path, const TableHeader& h0,
                               const std::function<void(PayloadSink&)>& fill) {
    AtomicFile out(path, "lattice table");
    FileSink sink(out);
    fill(sink);
    TableHeader h = h0;
    h.payload_bytes = sink.size();
    const std::uint64_t checksum = hash_bytes(h.metadata.data(), h.metadata.size(), sink.checksum());
    const auto header = encode_header(h, checksum);
    out.write_at(kTableHeaderBytes + sink.size(), h.metadata.data(), h.metadata.size());
    out.write_at(0, header.data(), header.size());
    out.commit();
    return sink.size();
}

TableHeader read_table_header(const std::string& path) {
    InputFile file(path, "lattice table", kMaxTableFileBytes);
    std::uint8_t buf[kTableHeaderBytes] = {};
    if (::pread(file.fd(), buf, sizeof buf, 0) < 0)
        throw InputError(path + ": cannot read lattice table");
    std::uint64_t checksum, meta;
    TableHeader h = decode_header(buf, static_cast<std::size_t>(file.size()), path, checksum, meta);
    h.metadata.resize(meta);
    const ssize_t m = ::pread(file.fd(), h.metadata.data(), meta,
                              static_cast<off_t>(kTableHeaderBytes + h.payload_bytes));
    if (m != static_cast<ssize_t>(meta)) throw InputError(path + ": cannot read lattice table metadata");
    return h;
}

LoadedTable load_table_file(const std::string& path, const TableHeader* expected,
                            const Shape* primitive) {
    InputFile file(path, "lattice table", kMaxTableFileBytes);
    const int fd = file.release();
    auto m = std::make_shared<Mapping>();
    m->size = static_cast<std::size_t>(file.size());
    if (m->size >= Mapping::kCopyAbove) {
        const bool ok = read_whole(fd, *m);
        const int err = errno;
        ::close(fd);
        if (!ok) throw InputError(path + ": cannot read lattice table: " + std::strerror(err));
    } else {
        if (m->size > 0) m->addr = ::mmap(nullptr, m->size, PROT_READ, MAP_PRIVATE, fd, 0);
        ::close(fd);
        if (m->size > 0 && m->addr == MAP_FAILED)
            throw InputError(path + ": cannot map lattice table: " + std::strerror(errno));
    }
    const std::uint8_t* bytes = m->bytes();
    std::uint64_t checksum = 0, meta_bytes = 0;
    LoadedTable out;
    out.header = decode_header(bytes, m->size, path, checksum, meta_bytes);
    TableHeader& h = out.header;
    if (expected) {
        if (h.encoding != expected->encoding || h.cells != expected->cells ||
            h.sigma_inv != expected->sigma_inv || h.cell != expected->cell)
            throw InputError(path + ": lattice table is for " + h.describe() + ", expected " +
                             expected->describe());
        if (h.fingerprint != expected->fingerprint)
            throw InputError(path + ": lattice table was built for another primitive "
                             "(its geometry fingerprint differs); rebuild it");
        h.coverage_rays = expected->coverage_rays;  // which the payload must have
    }
    const std::uint8_t* payload = bytes + kTableHeaderBytes;
    const std::uint8_t* meta = payload + h.payload_bytes;
    if (hash_bytes(meta, meta_bytes, hash_bytes(payload, h.payload_bytes)) != checksum)
        throw InputError(path + ": not a valid lattice table: payload checksum mismatch (corrupt)");
    h.metadata.assign(reinterpret_cast<const char*>(meta), meta_bytes);
    try {
        const Encoding& encoding = find_encoding(h.encoding);
        if (const std::uint32_t n = BoundaryGrid(h.cells).count(); n > encoding.max_points)
            throw std::runtime_error("the " + h.encoding + " encoding keys at most " +
                                     std::to_string(encoding.max_points) +
                                     " boundary points; the lattice has " + std::to_string(n));
        std::unique_ptr<LatticeTable> table =
            encoding.open(payload, h.payload_bytes, h.entries, h.context(primitive));
        table->hold(m);
        out.table = std::move(table);
        out.bytes = out.table->bytes() + kTableHeaderBytes + meta_bytes;
    } catch (const std::exception& e) {
        throw InputError(path + ": not a valid lattice table: " + e.what());
    }
    return out;
}

}  // namespace lat
