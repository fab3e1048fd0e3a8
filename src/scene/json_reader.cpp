#include "scene/json_reader.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include "util/error.h"
#include "util/file.h"

namespace lat {

void JsonValue::fail(const std::string& what) const {
    throw InputError(located_message(*file_, path_, what));
}

std::string JsonValue::type_name() const {
    if (j_->is_null()) return "null";
    if (j_->is_boolean()) return "a boolean";
    if (j_->is_number()) return "a number";
    if (j_->is_string()) return "a string";
    if (j_->is_array()) return "an array";
    return "an object";
}

bool JsonValue::has(const std::string& key) const {
    return j_->is_object() && j_->contains(key);
}

JsonValue JsonValue::at(const std::string& key) const {
    if (!j_->is_object()) fail("expected an object, found " + type_name());
    auto it = j_->find(key);
    if (it == j_->end()) fail("missing field '" + key + "'");
    return JsonValue(*it, path_.empty() ? key : path_ + "." + key, *file_);
}

std::optional<JsonValue> JsonValue::find(const std::string& key) const {
    if (!j_->is_object()) fail("expected an object, found " + type_name());
    auto it = j_->find(key);
    if (it == j_->end()) return std::nullopt;
    return JsonValue(*it, path_.empty() ? key : path_ + "." + key, *file_);
}

std::vector<std::string> JsonValue::keys() const {
    if (!j_->is_object()) fail("expected an object, found " + type_name());
    std::vector<std::string> out;
    for (auto it = j_->begin(); it != j_->end(); ++it) out.push_back(it.key());
    return out;
}

void JsonValue::allow_keys(const std::vector<const char*>& allowed, const std::string& owner) const {
    if (!j_->is_object()) fail("expected an object, found " + type_name());
    for (auto it = j_->begin(); it != j_->end(); ++it) {
        const std::string& k = it.key();
        if (k == "note" || k == "comment" || k == "description" || (!k.empty() && k[0] == '_'))
            continue;
        bool ok = false;
        for (const char* a : allowed) ok = ok || k == a;
        if (ok) continue;
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail("unknown field '" + k + "'" + (owner.empty() ? "" : " for " + owner) +
             " (expected one of: " + list + ")");
    }
}

std::size_t JsonValue::size() const {
    if (!j_->is_array()) fail("expected an array, found " + type_name());
    if (j_->size() > kMaxJsonArray)
        fail("array of " + std::to_string(j_->size()) + " entries is over the limit of " +
             std::to_string(kMaxJsonArray));
    return j_->size();
}

JsonValue JsonValue::operator[](std::size_t i) const {
    if (!j_->is_array()) fail("expected an array, found " + type_name());
    return JsonValue((*j_)[i], path_ + "[" + std::to_string(i) + "]", *file_);
}

double JsonValue::number() const {
    if (!j_->is_number()) fail("expected a number, found " + type_name());
    const double v = j_->get<double>();
    if (!std::isfinite(v)) fail("number is not finite");
    return v;
}

double JsonValue::positive() const {
    const double v = number();
    if (!(v > 0)) fail("must be positive, found " + j_->dump());
    return v;
}

double JsonValue::non_negative() const {
    const double v = number();
    if (v < 0) fail("must not be negative, found " + j_->dump());
    return v;
}

int JsonValue::integer() const {
    if (!j_->is_number()) fail("expected an integer, found " + type_name());
    const double v = j_->get<double>();
    if (v != std::floor(v) || std::abs(v) > 2e9) fail("expected an integer, found " + j_->dump());
    return static_cast<int>(v);
}

bool JsonValue::boolean() const {
    if (!j_->is_boolean()) fail("expected true or false, found " + type_name());
    return j_->get<bool>();
}

std::string JsonValue::string() const {
    if (!j_->is_string()) fail("expected a string, found " + type_name());
    return j_->get<std::string>();
}

Vec3 JsonValue::vec3() const {
    if (!j_->is_array() || j_->size() != 3) fail("expected [x, y, z], found " + (j_->is_array() ? "an array of " + std::to_string(j_->size()) : type_name()));
    return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
}

Vec3 JsonValue::colour() const {
    if (j_->is_number()) {
        const double v = non_negative();
        return {v, v, v};
    }
    if (!j_->is_array() || j_->size() != 3) fail("expected a colour [r, g, b], found " + type_name());
    return {(*this)[0].non_negative(), (*this)[1].non_negative(), (*this)[2].non_negative()};
}

Vec3 JsonValue::direction() const {
    const Vec3 v = vec3();
    if (length_squared(v) == 0.0) fail("must be a non-zero vector");
    return v;
}

Vec3 JsonValue::vec3_or(const std::string& key, Vec3 def) const {
    auto v = find(key);
    return v ? v->vec3() : def;
}

namespace {

// "file:line:col: what" for the byte at offset `at` (0-based) of text.
std::string text_place(const std::string& text, std::size_t at, const std::string& file) {
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i < at && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            col = 1;
        } else {
            ++col;
        }
    }
    return file + ":" + std::to_string(line) + ":" + std::to_string(col);
}

// A number token starting at text[i] (a '-' or a digit): its length.
std::size_t number_token_length(const std::string& text, std::size_t i) {
    std::size_t n = i;
    while (n < text.size() &&
           (std::isdigit(static_cast<unsigned char>(text[n])) || text[n] == '-' || text[n] == '+' ||
            text[n] == '.' || text[n] == 'e' || text[n] == 'E'))
        ++n;
    return n - i;
}

// What nlohmann's parser does not report with a place, or does not limit: nesting depth (the
// DOM and everything that walks it recurse, so a deep document could overflow the stack) and
// numbers beyond the range of a double (nlohmann throws out_of_range without a position).
// One linear pass over the raw text, skipping strings; syntax is left to the parser.
void prescan_json(const std::string& text, const std::string& file) {
    int depth = 0;
    bool in_string = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
            continue;
        }
        if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw InputError(text_place(text, i, file) + ": invalid JSON: nested deeper than " +
                                 std::to_string(kMaxJsonDepth) + " levels");
        } else if (c == ']' || c == '}') {
            --depth;
        } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
            const std::size_t len = number_token_length(text, i);
            const std::string token = text.substr(i, len);
            // strtod saturates to HUGE_VAL on overflow; underflow to 0 or a denormal is fine.
            if (std::isinf(std::strtod(token.c_str(), nullptr)))
                throw InputError(text_place(text, i, file) + ": number " + token.substr(0, 40) +
                                 " is out of the range of a double");
            i += len - 1;
        }
    }
}

}  // namespace

nlohmann::json parse_json_text(const std::string& text, const std::string& file) {
    prescan_json(text, file);
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        const std::size_t byte = e.byte > 0 ? e.byte - 1 : 0;  // e.byte is 1-based
        std::string what = e.what();
        // nlohmann's text: "[json.exception.parse_error.101] parse error at line 3, column 5:
        // syntax error while parsing value - invalid literal; last read: 'x'"; keep the reason.
        const auto pos = what.find("error while parsing");
        std::string reason = pos != std::string::npos ? what.substr(pos) : what;
        if (reason.rfind("error while ", 0) == 0) reason = "syntax " + reason;
        throw InputError(text_place(text, byte, file) + ": invalid JSON: " + reason);
    } catch (const nlohmann::json::exception& e) {
        // Anything else nlohmann can throw while parsing (the prescan should leave none).
        throw InputError(file + ": invalid JSON: " + e.what());
    }
}

nlohmann::json parse_json_file(const std::string& path) {
    return parse_json_text(read_text_file(path), path);
}

}  // namespace lat
