// Boned Blender FBX files in centimetres: their x100 unit scale sits in node transforms (the armature's,
// the mesh node's), which the raw mesh vertices leave out. The bind pose, the pose at time 0 and the mesh
// placed by its node (computed here from assimp's data, sharing no code with Character) agree in size.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <filesystem>

#include "sim/character/character.h"

namespace kf {
namespace {

const std::filesystem::path kModels = "/usr/share/assimp/models";

// Height (Y extent) of the file's meshes: raw (as stored) and placed by their nodes' global transforms.
struct Heights {
  double raw = 0, placed = 0;
};

Heights reference_heights(const std::filesystem::path& file) {
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  EXPECT_NE(s, nullptr) << file;
  if (!s) return {};
  double raw_lo = 1e30, raw_hi = -1e30, lo = 1e30, hi = -1e30;
  std::vector<const aiNode*> stack = {s->mRootNode};
  while (!stack.empty()) {
    const aiNode* n = stack.back();
    stack.pop_back();
    aiMatrix4x4 global;
    for (const aiNode* p = n; p; p = p->mParent) global = p->mTransformation * global;
    for (unsigned i = 0; i < n->mNumMeshes; ++i) {
      const aiMesh* mesh = s->mMeshes[n->mMeshes[i]];
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        raw_lo = std::min<double>(raw_lo, mesh->mVertices[v].y), raw_hi = std::max<double>(raw_hi, mesh->mVertices[v].y);
        const aiVector3D p = global * mesh->mVertices[v];
        lo = std::min<double>(lo, p.y), hi = std::max<double>(hi, p.y);
      }
    }
    for (unsigned c = 0; c < n->mNumChildren; ++c) stack.push_back(n->mChildren[c]);
  }
  return {raw_hi - raw_lo, hi - lo};
}

double height(const VecX& x) {
  double lo = 1e30, hi = -1e30;
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) lo = std::min(lo, x[3 * v + 1]), hi = std::max(hi, x[3 * v + 1]);
  return hi - lo;
}

class CharacterUnits : public ::testing::TestWithParam<const char*> {};

TEST_P(CharacterUnits, BindPosedAndNodePlacedHeightsAgree) {
  const std::filesystem::path file = kModels / GetParam();
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " missing: install Debian's assimp-testmodels";
  const Heights ref = reference_heights(file);
  Character c(file);
  VecX at0;
  c.pose(0.0, at0);
  std::printf("%s: raw mesh height %.4g, placed by its node %.4g, bind %.4g, posed at 0 s %.4g (file units)\n",
              GetParam(), ref.raw, ref.placed, height(c.bind_vertices()), height(at0));
  EXPECT_NEAR(height(at0), ref.placed, 0.01 * ref.placed);
  EXPECT_NEAR(height(c.bind_vertices()), height(at0), 1e-9 * height(at0));
  // The node transforms hold a scale of 100 the raw vertices lack (raw Y is Blender's depth here, so the
  // ratio is not exactly 100).
  EXPECT_GT(ref.placed, 30 * ref.raw);

  // scale 0.01 (the placement a scene's character.scale gives) makes every pose 100 times smaller.
  CharacterOptions cm;
  cm.placement = Affine(Eigen::Scaling(0.01));
  Character metres(file, cm);
  VecX m0;
  metres.pose(0.0, m0);
  EXPECT_NEAR(height(m0), 0.01 * height(at0), 1e-9 * height(at0));
  EXPECT_NEAR(height(metres.bind_vertices()), 0.01 * height(at0), 1e-9 * height(at0));
}

INSTANTIATE_TEST_SUITE_P(BlenderFbx, CharacterUnits,
                         ::testing::Values("FBX/huesitos.fbx", "FBX/animation_with_skeleton.fbx"));

}  // namespace
}  // namespace kf
