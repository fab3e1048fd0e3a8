// The one list of table encodings. Adding one: a folder encodings/<name>/ with its table and
// its descriptor (see docs/encodings.md, "Adding an encoding"), and its name in both lists here.
#include "lattice/encoding.h"

#include <cassert>
#include <cstring>

#include "util/error.h"

namespace lat {

extern const Encoding kHash14Encoding, kDenseEncoding, kCandidatesEncoding, kPerfect5Encoding,
    kPerfect6Encoding, kPerfect7Encoding, kLearnedEncoding, kCoverageEncoding;

std::span<const Encoding* const> encodings() {
    static const Encoding* const all[] = {
        &kHash14Encoding,   &kDenseEncoding,    &kCandidatesEncoding, &kPerfect5Encoding,
        &kPerfect6Encoding, &kPerfect7Encoding, &kLearnedEncoding, &kCoverageEncoding,
    };
    return all;
}

void BufferSink::write_at(std::size_t offset, const void* data, std::size_t n) {
    assert(offset <= buffer_.size() && n <= buffer_.size() - offset);
    if (n) std::memcpy(buffer_.data() + offset, data, n);
}

void encode_payload(const Encoding& enc, RawHits&& hits, const TableContext& ctx,
                    const EncodeOptions& opt, PayloadSink& sink) {
    if (enc.stream) {
        enc.stream(std::move(hits), ctx, opt, sink);
        return;
    }
    const ByteBuffer payload = enc.build(hits, ctx, opt);
    hits = {};
    sink.reserve(payload.size());
    sink.write_at(0, payload.data(), payload.size());
}

const Encoding& find_encoding(std::string_view name) {
    std::string known;
    for (const Encoding* e : encodings()) {
        if (e->name == name) return *e;
        known += (known.empty() ? "" : ", ") + std::string(e->name);
    }
    throw InputError("unknown table encoding '" + std::string(name) + "' (known: " + known + ")");
}

const Encoding& coverage_encoding() {
    for (const Encoding* e : encodings())
        if (e->coverage) return *e;
    assert(false && "an encoding stores coverage");
    return *encodings().front();
}

}  // namespace lat
