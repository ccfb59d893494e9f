#include "sim/character/character.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <unordered_map>

#include "core/error.h"
#include "core/file_name.h"
#include "core/mesh_import.h"

namespace kf {
namespace {

Affine to_affine(const aiMatrix4x4& m) {
  Affine a = Affine::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.matrix()(r, c) = m[r][c];
  return a;
}

// Value of a key list at time t: held before the first and after the last key.
template <class T, class Mix>
T sample_keys(const std::vector<double>& times, const std::vector<T>& values, double t, Mix mix) {
  if (values.size() == 1 || t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto i = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double span = times[i] - times[i - 1];
  const double a = span > 0.0 ? (t - times[i - 1]) / span : 0.0;
  return mix(values[i - 1], values[i], a);
}

Affine channel_local(const CharacterChannel& ch, double t) {
  const auto lerp = [](const Vec3& a, const Vec3& b, double s) -> Vec3 { return a + s * (b - a); };
  const Vec3 p = sample_keys(ch.position_times, ch.positions, t, lerp);
  const Vec3 s = sample_keys(ch.scale_times, ch.scales, t, lerp);
  const Eigen::Quaterniond q = sample_keys(
      ch.rotation_times, ch.rotations, t,
      [](const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double u) { return a.slerp(u, b); });
  Affine local = Affine::Identity();
  local.linear() = q.normalized().toRotationMatrix() * s.asDiagonal();
  local.translation() = p;
  return local;
}

// Vertices and triangles of all the scene's meshes together (faces that are not triangles skipped).
void count_geometry(const aiScene& scene, int& vertices, int& triangles) {
  vertices = triangles = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    vertices += static_cast<int>(scene.mMeshes[m]->mNumVertices);
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f)
      triangles += scene.mMeshes[m]->mFaces[f].mNumIndices == 3 ? 1 : 0;
  }
}

// The file's float weights sum to 1 only within ~1e-7; renormalised, a rigid motion of the whole
// skeleton moves every vertex rigidly to double precision. w: kMaxInfluences per vertex.
void renormalise_weights(double* w, unsigned vertices, int per_vertex) {
  for (unsigned v = 0; v < vertices; ++v, w += per_vertex) {
    double sum = 0.0;
    for (int k = 0; k < per_vertex; ++k) sum += w[k];
    if (sum > 0.0)
      for (int k = 0; k < per_vertex; ++k) w[k] /= sum;
  }
}

// The node holding mesh m (depth first from the root), or null.
const aiNode* node_of_mesh(const aiScene& scene, unsigned m) {
  const aiNode* mesh_node = nullptr;
  std::vector<const aiNode*> search = {scene.mRootNode};
  while (!search.empty() && !mesh_node) {
    const aiNode* n = search.back();
    search.pop_back();
    for (unsigned i = 0; i < n->mNumMeshes; ++i)
      if (n->mMeshes[i] == m) mesh_node = n;
    for (unsigned c = 0; c < n->mNumChildren; ++c) search.push_back(n->mChildren[c]);
  }
  return mesh_node;
}

}  // namespace

// Node hierarchy, parents first; by_name: node name -> index.
void Character::read_nodes(const aiScene& scene, std::unordered_map<std::string, int>& by_name) {
  std::vector<const aiNode*> stack = {scene.mRootNode};
  std::vector<int> stack_parent = {-1};
  while (!stack.empty()) {
    const aiNode* n = stack.back();
    const int parent = stack_parent.back();
    stack.pop_back();
    stack_parent.pop_back();
    const int index = static_cast<int>(nodes_.size());
    nodes_.push_back({n->mName.C_Str(), parent, to_affine(n->mTransformation), -1});
    by_name.emplace(n->mName.C_Str(), index);
    for (unsigned c = n->mNumChildren; c-- > 0;) {
      stack.push_back(n->mChildren[c]);
      stack_parent.push_back(index);
    }
  }
}

// Animation channels, times converted from ticks to seconds.
void Character::read_channels(const aiScene& scene, const aiAnimation* anim,
                              const std::unordered_map<std::string, int>& by_name) {
  const double tps = anim->mTicksPerSecond > 0.0 ? anim->mTicksPerSecond : 25.0;  // assimp's convention
  duration_ = anim->mDuration / tps;
  for (unsigned c = 0; c < anim->mNumChannels; ++c) {
    const aiNodeAnim* a = anim->mChannels[c];
    const auto it = by_name.find(a->mNodeName.C_Str());
    if (it == by_name.end()) continue;  // a channel for a node that does not exist moves nothing
    CharacterChannel ch;
    ch.node = it->second;
    aiVector3D rest_s, rest_p;
    aiQuaternion rest_q;
    scene.mRootNode->FindNode(a->mNodeName)->mTransformation.Decompose(rest_s, rest_q, rest_p);
    for (unsigned k = 0; k < a->mNumPositionKeys; ++k) {
      const auto& key = a->mPositionKeys[k];
      ch.position_times.push_back(key.mTime / tps);
      ch.positions.emplace_back(key.mValue.x, key.mValue.y, key.mValue.z);
    }
    for (unsigned k = 0; k < a->mNumRotationKeys; ++k) {
      const auto& key = a->mRotationKeys[k];
      ch.rotation_times.push_back(key.mTime / tps);
      ch.rotations.emplace_back(key.mValue.w, key.mValue.x, key.mValue.y, key.mValue.z);
    }
    for (unsigned k = 0; k < a->mNumScalingKeys; ++k) {
      const auto& key = a->mScalingKeys[k];
      ch.scale_times.push_back(key.mTime / tps);
      ch.scales.emplace_back(key.mValue.x, key.mValue.y, key.mValue.z);
    }
    // A missing key list means "as in the rest transform".
    if (ch.positions.empty()) ch.position_times.push_back(0.0), ch.positions.emplace_back(rest_p.x, rest_p.y, rest_p.z);
    if (ch.scales.empty()) ch.scale_times.push_back(0.0), ch.scales.emplace_back(rest_s.x, rest_s.y, rest_s.z);
    if (ch.rotations.empty())
      ch.rotation_times.push_back(0.0), ch.rotations.emplace_back(rest_q.w, rest_q.x, rest_q.y, rest_q.z);
    nodes_[ch.node].channel = static_cast<int>(channels_.size());
    channels_.push_back(std::move(ch));
  }
}

// Joined meshes, bones and per-vertex influences. name: the file, for messages.
void Character::read_meshes(const aiScene& scene, const std::unordered_map<std::string, int>& by_name,
                            const std::string& name) {
  int total_vertices = 0, total_triangles = 0;
  count_geometry(scene, total_vertices, total_triangles);
  raw_vertices_.resize(3 * total_vertices);
  triangles_.resize(total_triangles, 3);
  influence_bones_.assign(kMaxInfluences * total_vertices, 0);
  influence_weights_.assign(kMaxInfluences * total_vertices, 0.0);
  std::vector<int> slots_used(total_vertices, 0);
  int v0 = 0, t = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    mesh_names_.push_back(mesh->mName.C_Str());
    mesh_vertex_begin_.push_back(v0);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      raw_vertices_.segment<3>(3 * (v0 + v)) << mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by Triangulate carry no surface
      triangles_.row(t++) << v0 + static_cast<int>(face.mIndices[0]), v0 + static_cast<int>(face.mIndices[1]),
          v0 + static_cast<int>(face.mIndices[2]);
    }
    for (unsigned b = 0; b < mesh->mNumBones; ++b) {
      const aiBone* bone = mesh->mBones[b];
      const auto it = by_name.find(bone->mName.C_Str());
      if (it == by_name.end()) throw InputError(name + ": bone '" + printable(bone->mName.C_Str()) + "' has no node");
      const int bone_index = static_cast<int>(bones_.size());
      bones_.push_back({bone->mName.C_Str(), it->second, to_affine(bone->mOffsetMatrix)});
      for (unsigned w = 0; w < bone->mNumWeights; ++w) {
        const int v = v0 + static_cast<int>(bone->mWeights[w].mVertexId);
        if (bone->mWeights[w].mWeight == 0.0f || slots_used[v] >= kMaxInfluences) continue;
        influence_bones_[kMaxInfluences * v + slots_used[v]] = bone_index;
        influence_weights_[kMaxInfluences * v + slots_used[v]] = bone->mWeights[w].mWeight;
        ++slots_used[v];
      }
    }
    renormalise_weights(influence_weights_.data() + kMaxInfluences * v0, mesh->mNumVertices, kMaxInfluences);
    // Vertices no bone moves follow their mesh's node rigidly (a bone with an identity offset).
    const aiNode* mesh_node = node_of_mesh(scene, m);
    int rigid_bone = -1;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      if (slots_used[v0 + v] > 0) continue;
      if (rigid_bone < 0) {
        rigid_bone = static_cast<int>(bones_.size());
        bones_.push_back({mesh_node ? mesh_node->mName.C_Str() : "", mesh_node ? by_name.at(mesh_node->mName.C_Str()) : 0,
                          Affine::Identity()});
      }
      influence_bones_[kMaxInfluences * (v0 + v)] = rigid_bone;
      influence_weights_[kMaxInfluences * (v0 + v)] = 1.0;
    }
    v0 += static_cast<int>(mesh->mNumVertices);
  }
  mesh_vertex_begin_.push_back(v0);
}

Character::Character(const std::filesystem::path& file, const CharacterOptions& options)
    : options_(options), file_(file.string()) {
  const std::string name = printable(file.string());
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw InputError(name + ": character mesh not found (expected a file assimp can read, e.g. .X)");

  // An untrusted file: read in a child process (mesh_import.h), finite, indices checked.
  const std::unique_ptr<aiScene> owned = import_mesh_file(
      file, {aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights, kMaxInfluences});
  const aiScene* scene = owned.get();
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !scene->mRootNode || scene->mNumMeshes == 0)
    throw InputError(name + ": character file has no complete mesh");
  // A file without animation is a static body (animation 0 then means "none").
  const bool animated = scene->mNumAnimations > 0;
  if (options.animation < 0 || (animated && options.animation >= static_cast<int>(scene->mNumAnimations)) ||
      (!animated && options.animation != 0))
    throw InputError(name + ": animation " + std::to_string(options.animation) + " requested, file has " +
                     std::to_string(scene->mNumAnimations));

  std::unordered_map<std::string, int> by_name;
  read_nodes(*scene, by_name);
  if (animated) read_channels(*scene, scene->mAnimations[options.animation], by_name);
  read_meshes(*scene, by_name, name);  // every vertex gets a bone: its mesh's node's when no bone moves it
  if (bones_.empty()) throw InputError(name + ": character file has no bones");
  if (triangles_.rows() == 0) throw InputError(name + ": character file has no triangles");

  world_.assign(nodes_.size(), Affine::Identity());
  skin_.assign(bones_.size(), Eigen::Matrix<double, 3, 4>::Zero());
  scratch_a_.resize(raw_vertices_.size());
  scratch_b_.resize(raw_vertices_.size());
  pose(0.0, bind_vertices_);
  const Affine file_from_world = options_.placement.inverse();
  for (CharacterBone& b : bones_) b.bind = file_from_world * world_[size_t(b.node)];  // world_ at time 0
}

int Character::node_index(const std::string& name) const {
  for (size_t i = 0; i < nodes_.size(); ++i)
    if (nodes_[i].name == name) return static_cast<int>(i);
  return -1;
}

double Character::wrap_time(double t) const {
  if (duration_ <= 0.0) return 0.0;
  if (options_.wrap == TimeWrap::kClamp) return std::clamp(t, 0.0, duration_);
  double r = std::fmod(t, duration_);
  return r < 0.0 ? r + duration_ : r;
}

void Character::evaluate_nodes(double t) {
  const double tw = wrap_time(t);
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const CharacterNode& n = nodes_[i];
    const Affine local = n.channel >= 0 ? channel_local(channels_[n.channel], tw) : n.rest_local;
    world_[i] = n.parent < 0 ? options_.placement * local : world_[n.parent] * local;
  }
}

void Character::pose(double t, VecX& out) {
  evaluate_nodes(t);
  for (size_t b = 0; b < bones_.size(); ++b) skin_[b] = (world_[bones_[b].node] * bones_[b].offset).matrix().topRows<3>();
  if (out.size() != raw_vertices_.size()) out.resize(raw_vertices_.size());
  const int n = vertex_count();
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector4d p(raw_vertices_[3 * v], raw_vertices_[3 * v + 1], raw_vertices_[3 * v + 2], 1.0);
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < kMaxInfluences; ++k) {
      const double w = influence_weights_[kMaxInfluences * v + k];
      if (w != 0.0) x += w * (skin_[influence_bones_[kMaxInfluences * v + k]] * p);
    }
    out.segment<3>(3 * v) = x;
  }
}

void Character::velocities(double t, VecX& out, double dt) {
  double ta = t - 0.5 * dt, tb = t + 0.5 * dt;
  if (options_.wrap == TimeWrap::kClamp) {
    ta = wrap_time(ta);
    tb = wrap_time(tb);
  }
  if (out.size() != raw_vertices_.size()) out.resize(raw_vertices_.size());
  if (tb <= ta) {
    out.setZero();
    return;
  }
  pose(ta, scratch_a_);
  pose(tb, scratch_b_);
  out = (scratch_b_ - scratch_a_) / (tb - ta);
}

void Character::vertex_normals(const VecX& x, VecX& out) const {
  if (out.size() != x.size()) out.resize(x.size());
  out.setZero();
  for (int f = 0; f < triangle_count(); ++f) {
    const int a = triangles_(f, 0), b = triangles_(f, 1), c = triangles_(f, 2);
    const Vec3 area2 = (seg(x, b) - seg(x, a)).cross(seg(x, c) - seg(x, a));
    seg(out, a) += area2;
    seg(out, b) += area2;
    seg(out, c) += area2;
  }
  for (int v = 0; v < vertex_count(); ++v) {
    const double len = seg(out, v).norm();
    if (len > 0.0) seg(out, v) /= len;
  }
}

Affine Character::node_world(int node, double t) {
  evaluate_nodes(t);
  return world_.at(node);
}

}  // namespace kf
