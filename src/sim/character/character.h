#pragma once
// A skinned, animated character mesh loaded through assimp, posed by linear blend skinning.
//
// Frames and units are the asset's: for assets/character/BCN_Epileptic.X that is metres, Y up, facing +Z,
// pelvis near the origin, feet at y = -1.024 (use `CharacterOptions::placement` to stand it on y = 0).
// Time is in seconds; assimp's ticks are converted with the animation's ticks-per-second.
//
// All meshes of the file are joined into one vertex/triangle list (vertex indices offset per mesh).
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/types.h"

struct aiScene;
struct aiAnimation;

namespace kf {

using TriangleIndices = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;  // #T by 3 vertex indices
using Affine = Eigen::Affine3d;

// What happens to a time outside [0, duration].
enum class TimeWrap {
  kClamp,  // hold the first / last pose (default: clips for a blend are sub-ranges of one take)
  kLoop,   // t modulo duration (the take starts and ends in the same standing pose)
};

struct CharacterOptions {
  int animation = 0;                          // which of the file's animations drives the pose
  TimeWrap wrap = TimeWrap::kClamp;
  Affine placement = Affine::Identity();      // world-from-file transform applied after skinning
};

// One node of the transform hierarchy, stored parents-first (parent < own index; root has parent -1).
struct CharacterNode {
  std::string name;
  int parent = -1;
  Affine rest_local = Affine::Identity();  // the file's node transform (used when no channel drives it)
  int channel = -1;                        // index into Character::channels(), or -1
};

// Keys of one animated node, times in seconds (ascending). Each list has at least one key.
struct CharacterChannel {
  int node = -1;
  std::vector<double> position_times, rotation_times, scale_times;
  std::vector<Vec3> positions, scales;
  std::vector<Eigen::Quaterniond> rotations;
};

// A bone as used by one mesh: the node it follows and the offset (bone-from-mesh bind matrix).
struct CharacterBone {
  std::string name;
  int node = -1;
  Affine offset = Affine::Identity();
  Affine bind = Affine::Identity();  // its node in the bind pose (below), the file's frame
};

class Character {
 public:
  // Maximum bone influences per vertex kept after assimp's LimitBoneWeights step.
  static constexpr int kMaxInfluences = 4;

  // Loads `file` (any format assimp reads; meshes no bone moves follow their node, and a file without
  // animation is a static body of duration 0). Throws InputError naming the file when it is missing,
  // unreadable, truncated or has no mesh.
  explicit Character(const std::filesystem::path& file, const CharacterOptions& options = {});

  const std::string& file() const { return file_; }  // as given to the constructor, for messages
  int vertex_count() const { return static_cast<int>(bind_vertices_.size() / 3); }
  int triangle_count() const { return static_cast<int>(triangles_.rows()); }
  // Bind-pose vertices: 3n entries, file frame with `placement` applied. The bind pose is the pose at the
  // animation's time 0 (a static file's: its node transforms), posed as any time is: an FBX's unit scale
  // and axis turn sit in its node transforms, which its raw mesh vertices leave out.
  const VecX& bind_vertices() const { return bind_vertices_; }
  const TriangleIndices& triangles() const { return triangles_; }
  // First vertex / triangle of each joined mesh, plus a final entry equal to the total count.
  const std::vector<int>& mesh_vertex_begin() const { return mesh_vertex_begin_; }
  const std::vector<std::string>& mesh_names() const { return mesh_names_; }

  const std::vector<CharacterNode>& nodes() const { return nodes_; }
  const std::vector<CharacterChannel>& channels() const { return channels_; }
  const std::vector<CharacterBone>& bones() const { return bones_; }
  // Per-vertex influences, kMaxInfluences slots per vertex (unused slots: bone 0, weight 0).
  const std::vector<int>& influence_bones() const { return influence_bones_; }
  const std::vector<double>& influence_weights() const { return influence_weights_; }
  int node_index(const std::string& name) const;  // -1 when absent

  double duration() const { return duration_; }  // seconds
  TimeWrap wrap() const { return options_.wrap; }
  const Affine& placement() const { return options_.placement; }
  // Maps any time to the animation's [0, duration] by the wrap rule.
  double wrap_time(double t) const;

  // Skinned vertex positions at time t (seconds): out = 3n entries, metres, world frame.
  // Rotations are slerped and positions/scales lerped between keys. Allocation-free after the first
  // call (out is resized only if its size differs). Not thread-safe: it uses the object's scratch space.
  void pose(double t, VecX& out);
  // Vertex velocities at time t (3n, m/s) by a central difference of pose() over `dt` seconds
  // (one-sided at the ends in clamp mode). The keys are piecewise linear, so this is exact away from keys.
  void velocities(double t, VecX& out, double dt = 1e-4);
  // Area-weighted unit vertex normals (3n) of a posed vertex array x (3n). Allocation-free given sized out.
  void vertex_normals(const VecX& x, VecX& out) const;
  // World transform of node `node` at time t (the pelvis root gives the character's height).
  Affine node_world(int node, double t);

 private:
  void evaluate_nodes(double t);  // fills world_ at time t
  // Loading, in this order (the constructor).
  void read_nodes(const aiScene& scene, std::unordered_map<std::string, int>& by_name);
  void read_channels(const aiScene& scene, const aiAnimation* anim, const std::unordered_map<std::string, int>& by_name);
  void read_meshes(const aiScene& scene, const std::unordered_map<std::string, int>& by_name, const std::string& name);

  CharacterOptions options_;
  std::string file_;
  VecX raw_vertices_;   // as stored in the file (mesh frame), 3n
  VecX bind_vertices_;
  TriangleIndices triangles_;
  std::vector<int> mesh_vertex_begin_;
  std::vector<std::string> mesh_names_;
  std::vector<CharacterNode> nodes_;
  std::vector<CharacterChannel> channels_;
  std::vector<CharacterBone> bones_;
  std::vector<int> influence_bones_;
  std::vector<double> influence_weights_;
  double duration_ = 0.0;

  // Scratch, sized at load so posing allocates nothing.
  std::vector<Affine> world_;        // per node
  std::vector<Eigen::Matrix<double, 3, 4>> skin_;  // per bone: world(node) * offset
  VecX scratch_a_, scratch_b_;
};

}  // namespace kf
