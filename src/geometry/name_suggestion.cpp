#include "geometry/name_suggestion.h"

#include <algorithm>
#include <cctype>
#include <limits>

namespace lat {
namespace {

bool is_identifier(std::string_view s) {
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
    return std::all_of(s.begin(), s.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
}

bool equal_ignoring_case(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char p, char q) {
               return std::tolower(static_cast<unsigned char>(p)) ==
                      std::tolower(static_cast<unsigned char>(q));
           });
}

// Edit distance where swapping two neighbours counts as one edit (optimal string alignment).
std::size_t edit_distance(std::string_view a, std::string_view b) {
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
    for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i)
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[n][m];
}

// "xy" -> "x*y": the split of name into the fewest known names, if there are at least two.
std::string split_into_known(std::string_view name, const std::vector<std::string>& known) {
    constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
    const std::size_t n = name.size();
    // pieces[i]: fewest names that make up name[0, i); last[i]: index in known of the last one.
    std::vector<std::size_t> pieces{0}, last(n + 1, 0);
    pieces.resize(n + 1, kNone);
    for (std::size_t i = 1; i <= n; ++i)
        for (std::size_t k = 0; k < known.size(); ++k) {
            const std::size_t len = known[k].size();
            if (len > i || pieces[i - len] == kNone) continue;
            if (name.substr(i - len, len) != known[k]) continue;
            if (pieces[i - len] + 1 < pieces[i]) {
                pieces[i] = pieces[i - len] + 1;
                last[i] = k;
            }
        }
    if (pieces[n] == kNone || pieces[n] < 2) return "";
    std::vector<std::string_view> parts;
    for (std::size_t i = n; i > 0; i -= known[last[i]].size()) parts.push_back(known[last[i]]);
    std::string out;
    for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
        if (!out.empty()) out.push_back('*');
        out.append(*it);
    }
    return out;
}

}  // namespace

std::string suggest_name(std::string_view name, const std::vector<std::string>& all_known) {
    std::vector<std::string> known;
    for (const std::string& k : all_known)
        if (is_identifier(k) && k != name) known.push_back(k);

    for (const std::string& k : known)
        if (equal_ignoring_case(name, k)) return k;

    if (std::string split = split_into_known(name, known); !split.empty()) return split;

    // Only a few edits, and never a complete rewrite: "q" is not a typo of "x".
    const std::size_t allowed = std::max<std::size_t>(1, name.size() / 3);
    const std::string* best = nullptr;
    std::size_t best_distance = allowed + 1;
    for (const std::string& k : known) {
        const std::size_t d = edit_distance(name, k);
        if (d < best_distance && d < std::min(name.size(), k.size())) {
            best = &k;
            best_distance = d;
        }
    }
    return best ? *best : "";
}

}  // namespace lat
