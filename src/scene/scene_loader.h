#pragma once
// Reading scene files: "lattice/1" (docs/scene-format.md), a superset of the reference format
// "lattice-reference/1". Every user error throws InputError naming the file and the place.
#include <string>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace lat {

// progress: a bar on stderr while scatters that take longer than a second are placed.
Scene load_scene(const std::string& path, bool progress = false);
Scene load_scene_text(const std::string& text, const std::string& file, bool progress = false);

// The scene's primitive of that name; throws InputError naming the scene file and the names it
// has.
const Primitive& find_primitive(const Scene& scene, const std::string& name);

// Parts of the loader that other readers (e.g. Table 1 files, the Python module's camera edits)
// reuse.
Camera parse_camera(const JsonValue& v);
Transform parse_transform(const JsonValue& v);
// Throws InputError at v unless t and its inverse are finite (composing finite transforms, e.g.
// down a CSG tree, can overflow).
void require_finite_transform(const Transform& t, const JsonValue& v);
class ObjectParser;
// `objects` parses primitives given as an object; without it only chains are accepted.
Primitive parse_primitive(const JsonValue& v, const std::string& name,
                          const ObjectParser* objects = nullptr);

}  // namespace lat
