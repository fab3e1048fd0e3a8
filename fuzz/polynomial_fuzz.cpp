// Polynomial text -> Poly3 (parse_polynomial, with a few named constants), then a few rays
// through the surface, as a "quartic" object would be traced. Every input must parse or throw
// PolynomialParseError.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "fuzz_rays.h"
#include "geometry/named_shapes.h"
#include "geometry/polynomial_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    static const std::map<std::string, double> constants = {{"R", 2.0}, {"r", 0.5}, {"a", 1e300}};
    try {
        const lat::Poly3 f = lat::parse_polynomial(text, constants);
        if (f.degree() < 1) return 0;  // the scene reader refuses these
        const lat::PlacedShape s = lat::make_algebraic(f, lat::Bounds3::infinite());
        lat::fuzz::trace_a_few_rays(*s.shape, s.placement);
    } catch (const lat::PolynomialParseError&) {
    }
    return 0;
}
