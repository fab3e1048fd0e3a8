#pragma once
// Typed, located access to a JSON document (in the spirit of Mitsuba's typed parameter
// lookup): every value knows its file and its path, e.g. "objects[12].transform", so each
// error names the place, and unknown keys are reported instead of silently ignored.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "math/vec.h"

namespace lat {

class JsonValue {
public:
    JsonValue(const nlohmann::json& j, std::string path, const std::string& file)
        : j_(&j), path_(std::move(path)), file_(&file) {}

    const std::string& path() const { return path_; }
    const std::string& file() const { return *file_; }
    const nlohmann::json& raw() const { return *j_; }

    [[noreturn]] void fail(const std::string& what) const;

    bool is_object() const { return j_->is_object(); }
    bool is_array() const { return j_->is_array(); }
    bool is_string() const { return j_->is_string(); }
    bool is_number() const { return j_->is_number(); }

    // Object members. `at` requires the key; `find` returns nothing when absent.
    bool has(const std::string& key) const;
    JsonValue at(const std::string& key) const;
    std::optional<JsonValue> find(const std::string& key) const;
    // Fails on any key not in `allowed` (keys "note", "comment", "description" and those
    // starting with '_' are always allowed, for annotations).
    void allow_keys(std::initializer_list<const char*> allowed) const {
        allow_keys(std::vector<const char*>(allowed));
    }
    // As above; `owner` (e.g. "a torus") makes the message say what the keys are for.
    void allow_keys(const std::vector<const char*>& allowed, const std::string& owner = "") const;
    std::vector<std::string> keys() const;

    // Arrays.
    std::size_t size() const;  // requires an array
    JsonValue operator[](std::size_t i) const;

    double number() const;  // finite
    double positive() const;
    double non_negative() const;
    int integer() const;
    bool boolean() const;
    std::string string() const;
    Vec3 vec3() const;
    Vec3 colour() const;  // [r, g, b] with components >= 0, or one number for grey
    Vec3 direction() const;  // non-zero vec3

    // Typed lookup with default.
    Vec3 vec3_or(const std::string& key, Vec3 def) const;

private:
    const nlohmann::json* j_;
    std::string path_;
    const std::string* file_;

    std::string type_name() const;
};

// Deepest nesting of arrays and objects a document may have: deep enough for any real scene
// (a CSG level takes two), shallow enough that code walking the tree recursively is safe.
constexpr int kMaxJsonDepth = 1024;
// Longest array a scene may hold (objects, spheres, ...): far beyond real scenes, and it keeps
// sizes derived from array lengths well within int range.
constexpr std::size_t kMaxJsonArray = 10'000'000;

// Parses a whole file; syntax errors, nesting deeper than kMaxJsonDepth and numbers beyond the
// range of a double name the line and column.
nlohmann::json parse_json_file(const std::string& path);
nlohmann::json parse_json_text(const std::string& text, const std::string& file);

}  // namespace lat
