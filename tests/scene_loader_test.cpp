// The scene reader: a valid scene loads; every class of user error gives one message naming
// the file and the place in it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "geometry/parts.h"
#include "scene/scene_loader.h"
#include "test_paths.h"
#include "util/error.h"

namespace lat {
namespace {

using nlohmann::json;

json base_scene() {
    return json::parse(R"({
      "format": "lattice/1",
      "camera": {"eye": [0, -10, 2], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_y_deg": 40,
                 "width": 32, "height": 24},
      "background": [0.1, 0.1, 0.1],
      "lights": [{"position": [5, -5, 5], "intensity": [1, 1, 1]}],
      "materials": {"red": {"color": [1, 0, 0], "ka": 0.1, "kd": 0.8, "ks": 0.1, "shininess": 10}},
      "primitives": {"hair": {"spheres": [[0.5, 0.5, 0.5, 0.5], [0.5, 0.5, 2.5, 0.5]],
                              "cylinders": [[0, 1, 0.5]],
                              "lattice": {"sigma": 1, "cells": [1, 1, 3]}}},
      "objects": [
        {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "red"},
        {"type": "torus", "major_radius": 2, "minor_radius": 0.5, "material": "red",
         "transform": [{"rotate": {"axis": [1, 0, 0], "angle_deg": 30}}, {"translate": [0, 0, 1]}]},
        {"type": "quartic", "polynomial": "x^4 + y^4 + z^4 - R", "constants": {"R": 2},
         "material": "red"},
        {"type": "instance", "primitive": "hair", "material": "red",
         "transform": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]},
        {"type": "csg", "op": "difference", "material": "red", "children": [
          {"type": "sphere", "radius": 1},
          {"type": "halfspace", "point": [0, 0, 0], "normal": [0, 0, 1]}]}
      ]})");
}

std::string load_error(const json& j) {
    try {
        load_scene_text(j.dump(2), "scene.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

std::string load_error_text(const std::string& text) {
    try {
        load_scene_text(text, "scene.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(SceneLoader, ValidSceneLoads) {
    const Scene s = load_scene_text(base_scene().dump(), "scene.json");
    EXPECT_EQ(s.camera.width, 32);
    EXPECT_EQ(s.objects.size(), 5u);
    EXPECT_EQ(s.objects[3].primitive, 0);
    EXPECT_EQ(ShapeParts(*s.primitives[0].shape).part_count(), 3u);
    ASSERT_TRUE(s.primitives[0].lattice.has_value());
    EXPECT_EQ(s.primitives[0].lattice->cells[2], 3);
}

TEST(SceneLoader, ReferencePlatesLoad) {
    for (const char* f : {"examples/plate1-thistle-no-self-shading.json", "examples/plate2-thistle.json",
                          "examples/plate3-hair-closeup.json", "examples/plate4-fuzzy-sphere-1000.json"}) {
        const Scene s = load_scene(test::source_path(f));
        EXPECT_GT(s.objects.size(), 0u) << f;
    }
}

TEST(SceneLoaderErrors, JsonSyntaxErrorHasLineAndColumn) {
    const std::string msg = load_error_text("{\n  \"camera\": {\n    \"eye\": [0, 0, 0],,\n  }\n}");
    EXPECT_NE(msg.find("scene.json:3:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("invalid JSON"), std::string::npos) << msg;
}

TEST(SceneLoaderErrors, WrongType) {
    json j = base_scene();
    j["objects"][0]["radius"] = "big";
    EXPECT_EQ(load_error(j), "scene.json: objects[0].radius: expected a number, found a string");
}

TEST(SceneLoaderErrors, MissingField) {
    json j = base_scene();
    j["objects"][1].erase("minor_radius");
    EXPECT_EQ(load_error(j), "scene.json: objects[1]: missing field 'minor_radius'");
}

TEST(SceneLoaderErrors, UnknownNames) {
    json j = base_scene();
    j["objects"][0]["material"] = "blue";
    EXPECT_EQ(load_error(j), "scene.json: objects[0].material: unknown material 'blue' (known: red)");
    j = base_scene();
    j["objects"][3]["primitive"] = "fur";
    EXPECT_EQ(load_error(j), "scene.json: objects[3].primitive: unknown primitive 'fur' (known: hair)");
    j = base_scene();
    j["objects"][0]["type"] = "sphear";
    EXPECT_NE(load_error(j).find("scene.json: objects[0].type: unknown object type 'sphear'"),
              std::string::npos);
    j = base_scene();
    j["objects"][0]["raduis"] = 2;
    EXPECT_NE(load_error(j).find("scene.json: objects[0]: unknown field 'raduis' for a sphere"),
              std::string::npos);
}

TEST(SceneLoaderErrors, SingularTransform) {
    json j = base_scene();
    j["objects"][3]["transform"] = json::parse("[[1,0,0,0],[0,0,0,0],[0,0,1,0]]");
    EXPECT_NE(load_error(j).find("scene.json: objects[3].transform: matrix is singular"),
              std::string::npos);
    j = base_scene();
    j["objects"][1]["transform"][0] = json::parse(R"({"scale": [1, 0, 1]})");
    EXPECT_NE(load_error(j).find("objects[1].transform[0].scale: scale factors must be non-zero"),
              std::string::npos);
}

TEST(SceneLoaderErrors, NegativeRadius) {
    json j = base_scene();
    j["objects"][0]["radius"] = -1;
    EXPECT_EQ(load_error(j), "scene.json: objects[0].radius: must be positive, found -1");
    j = base_scene();
    j["primitives"]["hair"]["spheres"][1][3] = -0.5;
    EXPECT_EQ(load_error(j), "scene.json: primitives.hair.spheres[1][3]: must be positive, found -0.5");
}

TEST(SceneLoaderErrors, BadPolynomial) {
    json j = base_scene();
    j["objects"][2]["polynomial"] = "x^4 + (y^2 - 1";
    const std::string msg = load_error(j);
    EXPECT_NE(msg.find("scene.json: objects[2].polynomial: column "), std::string::npos) << msg;
    j["objects"][2]["polynomial"] = "x^5 + y - 1";
    const std::string deg = load_error(j);
    EXPECT_NE(deg.find("scene.json: objects[2].polynomial:"), std::string::npos) << deg;
    EXPECT_NE(deg.find("degree 5"), std::string::npos) << deg;
    j["objects"][2]["polynomial"] = "x^4 + q";
    EXPECT_NE(load_error(j).find("'q'"), std::string::npos);
}

TEST(SceneLoaderErrors, CylinderNamesMissingSphere) {
    json j = base_scene();
    j["primitives"]["hair"]["cylinders"][0][1] = 7;
    EXPECT_EQ(load_error(j),
              "scene.json: primitives.hair.cylinders[0][1]: sphere index 7 does not exist (the "
              "primitive has 2 spheres, numbered from 0)");
}

TEST(SceneLoaderErrors, CsgProblems) {
    json j = base_scene();
    j["objects"][4]["op"] = "xor";
    EXPECT_NE(load_error(j).find("objects[4].op: unknown operation 'xor'"), std::string::npos);
    j = base_scene();
    j["objects"][4].erase("material");
    EXPECT_EQ(load_error(j), "scene.json: objects[4].children[0]: missing field 'material' (needed "
                             "unless an enclosing csg node sets one)");
    j = base_scene();
    j["objects"][4]["children"] = json::array();
    EXPECT_NE(load_error(j).find("objects[4].children: a csg node needs at least one child"),
              std::string::npos);
}

TEST(SceneLoaderErrors, CameraProblems) {
    json j = base_scene();
    j["camera"]["width"] = 0;
    EXPECT_NE(load_error(j).find("camera.width: must be between 1 and"), std::string::npos);
    j = base_scene();
    j["camera"]["up"] = json::array({0, 1, 0});
    j["camera"]["eye"] = json::array({0, -10, 0});
    EXPECT_NE(load_error(j).find("camera.up: up is parallel"), std::string::npos);
    j = base_scene();
    j["camera"]["width"] = 2.5;
    EXPECT_NE(load_error(j).find("camera.width: expected an integer, found 2.5"), std::string::npos);
}

TEST(SceneLoaderErrors, MissingFile) {
    try {
        load_scene("/nonexistent/dir/scene.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "/nonexistent/dir/scene.json: cannot open scene file: No such file or directory");
    }
}

}  // namespace
}  // namespace lat
