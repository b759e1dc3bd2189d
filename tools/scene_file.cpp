#include "tools/scene_file.h"

#include <climits>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "layout/message_text.h"
#include "meshcast/errors.h"
#include "tools/common.h"

namespace meshcast::tools {

namespace {

using nlohmann::json;

// What a JSON value is, for a message: its type, a number or a string
// shown short; never the value dumped whole (a nested array 100,000 deep
// would take the serializer's recursion past the stack).
std::string described(const json& value) {
  if (value.is_string()) return "the string \"" + shown_text(value.get<std::string>()) + "\"";
  if (value.is_number()) return "the number " + number_text(value.get<double>());
  if (value.is_array()) return "an array of " + std::to_string(value.size());
  if (value.is_object()) return "an object";
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  return "null";
}

// The numbers of an array field of `count` entries, or InputError naming it.
std::vector<double> numbers(const json& value, size_t count, const std::string& where) {
  if (!value.is_array() || value.size() != count)
    throw InputError(where + " is " + described(value) + ", not an array of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (const json& v : value) {
    if (!v.is_number()) throw InputError(where + " holds " + described(v) + ", not a number");
    out.push_back(v.get<double>());
  }
  return out;
}

// The file parsed, a key twice in one object refused (nlohmann keeps the
// last one silently, which would hide a misedited scene's first value).
json parse_refusing_duplicates(std::istream& in, const std::string& path) {
  std::vector<std::set<std::string>> keys;  // the keys seen, one set an object open
  auto callback = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    if (event == json::parse_event_t::object_end) keys.pop_back();
    if (event == json::parse_event_t::key && !keys.back().insert(parsed.get<std::string>()).second)
      throw InputError(path + ": the key \"" + shown_text(parsed.get<std::string>()) + "\" appears twice in one object");
    return true;
  };
  try {
    return json::parse(in, callback);
  } catch (const json::exception& e) {
    // nlohmann's message quotes the last token read: a 5 MB string's whole.
    throw InputError(path + ": not JSON: " + shown_text(e.what(), 200));
  }
}

}  // namespace

bool is_scene_file(const std::string& path) { return std::filesystem::path(path).extension() == ".json"; }

SceneFile load_scene_file(const std::string& path, const LayoutArgs& layout, std::FILE* report) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot be opened");
  const json doc = parse_refusing_duplicates(in, path);
  if (!doc.is_object() || !doc.contains("meshes") || !doc["meshes"].is_object() || !doc.contains("instances") ||
      !doc["instances"].is_array())
    throw InputError(path + ": a scene file is an object with \"meshes\" (an object) and \"instances\" (an array)");
  // A misspelt key would otherwise leave its field at the default unseen.
  for (const auto& [key, value] : doc.items())
    if (key != "meshes" && key != "instances") throw InputError(path + ": \"" + shown_text(key) + "\" is not a scene file's key (meshes, instances)");
  SceneFile out;
  std::map<std::string, MeshId> ids;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  for (const auto& [name, file] : doc["meshes"].items()) {
    const std::string where = path + ": meshes." + shown_text(name);
    if (!file.is_string()) throw InputError(where + " is " + described(file) + ", not a file name");
    if (file.get<std::string>().find('\0') != std::string::npos)
      throw InputError(where + ": the file name \"" + shown_text(file.get<std::string>()) + "\" holds a NUL character");
    // The mesh file's own messages name its path: one longer than a path may
    // be is refused here, shown short, rather than echoed whole by them.
    if (file.get<std::string>().size() > PATH_MAX)
      throw InputError(where + ": the file name \"" + shown_text(file.get<std::string>()) + "\" is longer than a path may be (" +
                       std::to_string(PATH_MAX) + " bytes)");
    // A generated mesh's name is that mesh wherever the scene file lies, as on the command line.
    const std::string mesh_path =
        is_generated_mesh(file.get<std::string>()) ? file.get<std::string>() : (folder / file.get<std::string>()).string();
    try {  // the mesh file's own message, and where the scene names it
      Loaded mesh = load_input(mesh_path, layout, report);
      out.blob_bytes += mesh.blob.size();
      ids[name] = out.scene.add_mesh(std::move(mesh.blob), mesh_path);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    out.mesh_names.push_back(name);
  }
  size_t index = 0;
  for (const json& i : doc["instances"]) {
    const std::string where = path + ": instances[" + std::to_string(index++) + "]";
    if (!i.is_object() || !i.contains("mesh") || !i["mesh"].is_string())
      throw InputError(where + " is not an object with a \"mesh\" name");
    for (const auto& [key, value] : i.items())
      if (key != "mesh" && key != "rotation_scale" && key != "translation" && key != "mask" && key != "enabled" &&
          key != "flip_facing")
        throw InputError(where + ": \"" + shown_text(key) +
                         "\" is not an instance's key (mesh, rotation_scale, translation, mask, enabled, flip_facing)");
    const auto mesh = ids.find(i["mesh"].get<std::string>());
    if (mesh == ids.end()) throw InputError(where + ".mesh: \"" + shown_text(i["mesh"].get<std::string>()) + "\" is not in \"meshes\"");
    Transform t;
    if (i.contains("rotation_scale")) {
      const std::vector<double> m = numbers(i["rotation_scale"], 9, where + ".rotation_scale");
      for (int k = 0; k < 9; ++k) t.rotation_scale[k] = float(m[size_t(k)]);
    }
    if (i.contains("translation")) {
      const std::vector<double> v = numbers(i["translation"], 3, where + ".translation");
      for (int k = 0; k < 3; ++k) t.translation[k] = v[size_t(k)];
    }
    uint8_t mask = 0xFF;
    if (i.contains("mask")) {
      if (!i["mask"].is_number_integer() || i["mask"].get<int64_t>() < 0 || i["mask"].get<int64_t>() > 255)
        throw InputError(where + ".mask is not an integer in 0..255");
      mask = uint8_t(i["mask"].get<int64_t>());
    }
    for (const char* flag : {"enabled", "flip_facing"})
      if (i.contains(flag) && !i[flag].is_boolean())
        throw InputError(where + "." + flag + " is " + described(i[flag]) + ", not true or false");
    const bool flip_facing = i.contains("flip_facing") && i["flip_facing"].get<bool>();
    InstanceId id;
    try {
      id = out.scene.add_instance(mesh->second, t, mask, flip_facing);
    } catch (const UsageError& e) {
      throw InputError(where + ": " + e.what());
    }
    if (i.contains("enabled") && !i["enabled"].get<bool>()) out.scene.set_enabled(id, false);
    ++out.instances;
  }
  out.scene.commit();
  return out;
}

}  // namespace meshcast::tools
