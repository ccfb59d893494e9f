#include "sim/character/asset_summary.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/file_name.h"
#include "core/mesh_import.h"
#include "sim/character/character.h"

namespace kf {
namespace {

Affine to_affine(const aiMatrix4x4& m) {
  Affine a = Affine::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.matrix()(r, c) = m[r][c];
  return a;
}

void grow(Vec3& lo, Vec3& hi, const Vec3& p, bool first) {
  lo = first ? p : lo.cwiseMin(p);
  hi = first ? p : hi.cwiseMax(p);
}

// The file's up axis and unit as its metadata states them (FBX and COLLADA do; .X and .obj do not).
void read_metadata(const aiScene& scene, AssetSummary& s) {
  if (!scene.mMetaData) return;
  int32_t axis = -1, sign = 1;
  double scale = 0;
  if (scene.mMetaData->Get("UpAxis", axis) && axis >= 0 && axis <= 2) {
    scene.mMetaData->Get("UpAxisSign", sign);
    s.up_axis = std::string(sign < 0 ? "-" : "+") + "XYZ"[axis];
  }
  float f = 0;
  if (scene.mMetaData->Get("UnitScaleFactor", f) && f > 0) scale = f / 100.0;  // FBX: centimetres per unit
  else if (scene.mMetaData->Get("UnitScaleFactor", scale) && scale > 0) scale /= 100.0;
  s.unit_scale = scale;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

std::string fmt(const Vec3& v) { return "(" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ")"; }

// Nodes, parents first, with their bind-pose positions; `by_name` gets each node's index, `placed` each
// mesh's transform to the file's frame (its node's, through its parents; identity for a mesh no node holds).
void read_nodes(const aiScene& scene, AssetSummary& s, std::map<std::string, int>& by_name,
                std::vector<Affine>& placed) {
  std::vector<Affine> world;
  placed.assign(scene.mNumMeshes, Affine::Identity());
  std::vector<bool> seen(scene.mNumMeshes, false);
  std::vector<std::pair<const aiNode*, int>> stack = {{scene.mRootNode, -1}};
  while (!stack.empty()) {
    const auto [n, parent] = stack.back();
    stack.pop_back();
    AssetNode node;
    node.name = n->mName.C_Str();
    node.parent = parent;
    node.depth = parent < 0 ? 0 : s.nodes[size_t(parent)].depth + 1;
    node.meshes = int(n->mNumMeshes);
    world.push_back(parent < 0 ? to_affine(n->mTransformation) : world[size_t(parent)] * to_affine(n->mTransformation));
    node.position = world.back().translation();
    for (unsigned i = 0; i < n->mNumMeshes; ++i)
      if (n->mMeshes[i] < scene.mNumMeshes && !seen[n->mMeshes[i]]) seen[n->mMeshes[i]] = true, placed[n->mMeshes[i]] = world.back();
    by_name.emplace(node.name, int(s.nodes.size()));
    s.nodes.push_back(node);
    for (unsigned c = n->mNumChildren; c-- > 0;) stack.push_back({n->mChildren[c], int(s.nodes.size()) - 1});
  }
}

// Each mesh's counts and box where its node places it (an FBX's unit scale sits in its node transforms),
// the whole file's box, and which nodes are bones (at their bind pose).
void read_meshes(const aiScene& scene, AssetSummary& s, const std::map<std::string, int>& by_name,
                 const std::vector<Affine>& placed) {
  bool first = true;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    AssetMesh out;
    out.name = mesh->mName.C_Str();
    out.vertices = int(mesh->mNumVertices);
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) out.triangles += mesh->mFaces[f].mNumIndices == 3 ? 1 : 0;
    out.bones = int(mesh->mNumBones);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const Vec3 p = placed[m] * Vec3(mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z);
      grow(out.lo, out.hi, p, v == 0);
      grow(s.lo, s.hi, p, first);
      first = false;
    }
    for (unsigned b = 0; b < mesh->mNumBones; ++b) {
      const auto it = by_name.find(mesh->mBones[b]->mName.C_Str());
      if (it == by_name.end()) continue;
      AssetNode& node = s.nodes[size_t(it->second)];
      node.bone = true;
      // A bone's bind pose: the inverse of its offset (bone-from-mesh) matrix, where the mesh is placed.
      node.position = (placed[m] * to_affine(mesh->mBones[b]->mOffsetMatrix).inverse()).translation();
    }
    s.meshes.push_back(out);
  }
}

// Each animation's length and channels; the nodes they move are marked animated.
void read_animations(const aiScene& scene, AssetSummary& s, const std::map<std::string, int>& by_name) {
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation* anim = scene.mAnimations[a];
    AssetAnimation out;
    out.name = anim->mName.C_Str();
    out.ticks = anim->mDuration;
    out.ticks_per_second = anim->mTicksPerSecond;
    out.seconds = anim->mDuration / (anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25.0);
    out.channels = int(anim->mNumChannels);
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
      const auto it = by_name.find(anim->mChannels[c]->mNodeName.C_Str());
      if (it != by_name.end()) s.nodes[size_t(it->second)].animated = true;
    }
    s.animations.push_back(out);
  }
}

// Bounds and bone positions as a scene's character poses the file at its bind pose (Character: the
// animation's time 0, skinned), when it loads as one; a file that does not keeps its meshes where their
// nodes place them.
void place_as_posed(const std::filesystem::path& file, AssetSummary& s, const std::map<std::string, int>& by_name) {
  std::unique_ptr<Character> c;
  try {
    c = std::make_unique<Character>(file);
  } catch (const InputError&) {
    return;
  }
  if (c->mesh_names().size() != s.meshes.size()) return;
  const VecX& x = c->bind_vertices();
  for (size_t m = 0; m < s.meshes.size(); ++m)
    for (int v = c->mesh_vertex_begin()[m]; v < c->mesh_vertex_begin()[m + 1]; ++v) {
      grow(s.meshes[m].lo, s.meshes[m].hi, seg(x, v), v == c->mesh_vertex_begin()[m]);
      grow(s.lo, s.hi, seg(x, v), v == 0);
    }
  for (const CharacterBone& b : c->bones()) {
    const auto it = by_name.find(c->nodes()[size_t(b.node)].name);
    if (it != by_name.end() && s.nodes[size_t(it->second)].bone) s.nodes[size_t(it->second)].position = b.bind.translation();
  }
}

// The height a scene gets from the file along each axis it may call up, in file units and, at the units the
// file states, in metres: what character.scale and character.up_axis choose between.
std::string height_text(const AssetSummary& s) {
  const Vec3 size = s.hi - s.lo;
  std::string out = "height: " + fmt(size.y()) + " along Y (up_axis \"y\"), " + fmt(size.z()) +
                    " along Z (up_axis \"z\") file units";
  if (s.unit_scale > 0)
    out += "; at its stated units (scale " + fmt(s.unit_scale) + ") " + fmt(s.unit_scale * size.y()) + " m and " +
           fmt(s.unit_scale * size.z()) + " m";
  return out;
}

}  // namespace

AssetSummary summarize_asset(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError(printable(name) + ": file not found");
  // An untrusted file: read in a child process (mesh_import.h), finite, indices checked.
  const std::unique_ptr<aiScene> owned = import_mesh_file(
      file, {aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights,
             Character::kMaxInfluences});
  const aiScene* scene = owned.get();
  AssetSummary s;
  s.file = name;
  read_metadata(*scene, s);
  std::map<std::string, int> by_name;
  std::vector<Affine> placed;
  read_nodes(*scene, s, by_name, placed);
  read_meshes(*scene, s, by_name, placed);
  read_animations(*scene, s, by_name);
  place_as_posed(file, s, by_name);
  return s;
}

nlohmann::json asset_json(const AssetSummary& s) {
  using nlohmann::json;
  auto vec = [](const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); };
  json j;
  j["file"] = s.file;
  j["up_axis"] = s.up_axis.empty() ? json(nullptr) : json(s.up_axis);
  j["metres_per_unit"] = s.unit_scale > 0 ? json(s.unit_scale) : json(nullptr);
  j["bounds"] = {{"min", vec(s.lo)}, {"max", vec(s.hi)}, {"size", vec(s.hi - s.lo)}};
  j["meshes"] = json::array();
  for (const AssetMesh& m : s.meshes)
    j["meshes"].push_back({{"name", m.name},
                           {"vertices", m.vertices},
                           {"triangles", m.triangles},
                           {"bones", m.bones},
                           {"bounds", {{"min", vec(m.lo)}, {"max", vec(m.hi)}}}});
  j["nodes"] = json::array();
  for (const AssetNode& n : s.nodes)
    j["nodes"].push_back({{"name", n.name},
                          {"parent", n.parent < 0 ? json(nullptr) : json(s.nodes[size_t(n.parent)].name)},
                          {"bone", n.bone},
                          {"animated", n.animated},
                          {"meshes", n.meshes},
                          {"position", vec(n.position)}});
  j["animations"] = json::array();
  for (size_t a = 0; a < s.animations.size(); ++a) {
    const AssetAnimation& an = s.animations[a];
    j["animations"].push_back({{"index", a},
                               {"name", an.name},
                               {"seconds", an.seconds},
                               {"ticks", an.ticks},
                               {"ticks_per_second", an.ticks_per_second},
                               {"channels", an.channels}});
  }
  return j;
}

std::string asset_text(const AssetSummary& s) {
  std::ostringstream os;
  const int bones = int(std::count_if(s.nodes.begin(), s.nodes.end(), [](const AssetNode& n) { return n.bone; }));
  os << s.file << "\n";
  os << "  bounds " << fmt(s.lo) << " to " << fmt(s.hi) << ", size " << fmt(s.hi - s.lo)
     << " (file units, the bind pose as a scene poses it)\n";
  os << "  up axis: " << (s.up_axis.empty() ? "not stated (keyframe takes +Y)" : s.up_axis)
     << "; units: " << (s.unit_scale > 0 ? fmt(s.unit_scale) + " m each" : "not stated (keyframe takes metres)") << "\n";
  os << "  " << height_text(s) << "\n";
  os << "meshes (" << s.meshes.size() << "; a character's anchors name one as \"mesh\"):\n";
  for (const AssetMesh& m : s.meshes)
    os << "  " << (m.name.empty() ? "(unnamed)" : m.name) << ": " << m.vertices << " vertices, " << m.triangles
       << " triangles, " << m.bones << " bones, bounds " << fmt(m.lo) << " to " << fmt(m.hi) << "\n";
  os << "animations (" << s.animations.size() << "; a character's \"animation\" is the index):\n";
  for (size_t a = 0; a < s.animations.size(); ++a) {
    const AssetAnimation& an = s.animations[a];
    os << "  " << a << " " << (an.name.empty() ? "(unnamed)" : "'" + an.name + "'") << ": " << fmt(an.seconds)
       << " s (" << fmt(an.ticks) << " ticks at " << fmt(an.ticks_per_second > 0 ? an.ticks_per_second : 25.0)
       << " a second" << (an.ticks_per_second > 0 ? "" : ", the file states none") << "), " << an.channels
       << " channels\n";
  }
  os << "nodes (" << s.nodes.size() << ", " << bones << " bones; [bone] moves vertices, [animated] has a channel; "
     << "position in the bind pose):\n";
  for (const AssetNode& n : s.nodes) {
    os << "  " << std::string(size_t(2 * std::min(n.depth, 20)), ' ') << (n.name.empty() ? "(unnamed)" : n.name);
    if (n.bone) os << " [bone]";
    if (n.animated) os << " [animated]";
    if (n.meshes > 0) os << " [" << n.meshes << " mesh" << (n.meshes > 1 ? "es" : "") << "]";
    os << " " << fmt(n.position) << "\n";
  }
  return os.str();
}

}  // namespace kf
