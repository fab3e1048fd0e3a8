#pragma once
// "Did you mean" hints for unknown names in the polynomial parser.
#include <string>
#include <string_view>
#include <vector>

namespace lat {

// A likely intended spelling of `name` among `known`, or "" if nothing is close:
// a case-insensitive match ("PI" -> "pi"), then a product of known names written without
// '*' ("xy" -> "x*y", "Rz" -> "R*z"), then a name within a small edit distance
// ("raduis" -> "radius"). Known names that are not identifiers are ignored.
std::string suggest_name(std::string_view name, const std::vector<std::string>& known);

}  // namespace lat
