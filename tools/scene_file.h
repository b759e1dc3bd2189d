// Scene files (README "Files"): a JSON object
//   {"meshes": {"NAME": "mesh or blob file", ...},
//    "instances": [{"mesh": "NAME", "rotation_scale": [9 numbers, row-major],
//                   "translation": [x, y, z], "mask": 255, "enabled": true,
//                   "flip_facing": false}, ...]}
// where rotation_scale (default the identity), translation (default 0),
// mask (default 255), enabled (default true) and flip_facing (default
// false: the instance faces as its mesh, Scene::add_instance) may be left
// out, and a mesh's path is taken relative to the scene file's folder (a
// generated mesh's name, terrain_2M, terrain_66k or city_1M, is that mesh).
#pragma once
#include <cstdio>
#include <string>
#include <vector>

#include "meshcast/scene.h"
#include "tools/commands.h"

namespace meshcast::tools {

struct SceneFile {
  Scene scene;  // committed
  std::vector<std::string> mesh_names;
  size_t instances = 0;
  uint64_t blob_bytes = 0;  // every mesh's blob once
};

// Reads the file, builds each mesh with `layout` (a blob file is taken as
// it is) and places the instances. InputError naming the file and the
// field for anything malformed: not JSON, a missing or mistyped field, an
// unknown mesh name, a transform Scene refuses.
SceneFile load_scene_file(const std::string& path, const LayoutArgs& layout, std::FILE* report);

// Whether `path` names a scene file (its name ends in .json).
bool is_scene_file(const std::string& path);

}  // namespace meshcast::tools
