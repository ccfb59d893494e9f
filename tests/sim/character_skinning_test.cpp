// Linear blend skinning against an independent evaluation straight from assimp's data structures.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>

#include "sim/character/character.h"
#include "character_test_util.h"

namespace kf {
namespace {

// Reference: assimp's own float types and interpolation, a linear key search, and the parent chain
// walked upwards per bone. Shares no code with Character.
class ReferenceSkinning {
 public:
  ReferenceSkinning() {
    scene_ = importer_.ReadFile(test::character_asset().string(),
                                aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights |
                                    aiProcess_PopulateArmatureData);
  }
  const aiScene* scene() const { return scene_; }

  VecX pose(double seconds) const {
    const aiAnimation* anim = scene_->mAnimations[0];
    const double tick = seconds * anim->mTicksPerSecond;
    std::vector<Vec3> out;
    for (unsigned m = 0; m < scene_->mNumMeshes; ++m) {
      const aiMesh* mesh = scene_->mMeshes[m];
      std::vector<aiVector3D> acc(mesh->mNumVertices, aiVector3D(0, 0, 0));
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        const aiMatrix4x4 skin = global(scene_->mRootNode->FindNode(bone->mName), tick) * bone->mOffsetMatrix;
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const auto& vw = bone->mWeights[w];
          acc[vw.mVertexId] += vw.mWeight * (skin * mesh->mVertices[vw.mVertexId]);
        }
      }
      for (const auto& a : acc) out.emplace_back(a.x, a.y, a.z);
    }
    VecX x(3 * out.size());
    for (size_t i = 0; i < out.size(); ++i) x.segment<3>(3 * i) = out[i];
    return x;
  }

 private:
  aiMatrix4x4 global(const aiNode* node, double tick) const {
    aiMatrix4x4 g;  // identity
    for (const aiNode* n = node; n; n = n->mParent) g = local(n, tick) * g;
    return g;
  }
  aiMatrix4x4 local(const aiNode* node, double tick) const {
    const aiAnimation* anim = scene_->mAnimations[0];
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
      const aiNodeAnim* ch = anim->mChannels[c];
      if (ch->mNodeName != node->mName) continue;
      const aiVector3D p = lerp_keys(ch->mPositionKeys, ch->mNumPositionKeys, tick);
      const aiVector3D s = lerp_keys(ch->mScalingKeys, ch->mNumScalingKeys, tick);
      aiQuaternion q = ch->mRotationKeys[0].mValue;
      for (unsigned k = 0; k + 1 < ch->mNumRotationKeys; ++k) {
        const auto &k0 = ch->mRotationKeys[k], &k1 = ch->mRotationKeys[k + 1];
        if (tick >= k1.mTime) q = k1.mValue;
        else if (tick >= k0.mTime) {
          aiQuaternion::Interpolate(q, k0.mValue, k1.mValue, static_cast<float>((tick - k0.mTime) / (k1.mTime - k0.mTime)));
          break;
        }
      }
      return aiMatrix4x4(s, q.Normalize(), p);
    }
    return node->mTransformation;
  }
  static aiVector3D lerp_keys(const aiVectorKey* keys, unsigned n, double tick) {
    aiVector3D v = keys[0].mValue;
    for (unsigned k = 0; k + 1 < n; ++k) {
      if (tick >= keys[k + 1].mTime) v = keys[k + 1].mValue;
      else if (tick >= keys[k].mTime) {
        const float a = static_cast<float>((tick - keys[k].mTime) / (keys[k + 1].mTime - keys[k].mTime));
        return keys[k].mValue + a * (keys[k + 1].mValue - keys[k].mValue);
      }
    }
    return v;
  }

  Assimp::Importer importer_;
  const aiScene* scene_ = nullptr;
};

TEST(CharacterSkinning, PoseAtZeroIsTheBindPose) {
  Character c(test::character_asset());
  VecX x;
  c.pose(0.0, x);
  ASSERT_EQ(x.size(), c.bind_vertices().size());
  // The file's data are single precision: 1e-5 m is a few float ulps of a 1 m coordinate chain.
  EXPECT_LT((x - c.bind_vertices()).cwiseAbs().maxCoeff(), 1e-5);
}

TEST(CharacterSkinning, MatchesIndependentEvaluationAtSeveralTimes) {
  Character c(test::character_asset());
  ReferenceSkinning ref;
  ASSERT_NE(ref.scene(), nullptr);
  VecX x;
  for (double t : {0.37, 1.0, 1.234, 1.7, 2.9, 3.3}) {
    c.pose(t, x);
    const VecX expected = ref.pose(t);
    ASSERT_EQ(x.size(), expected.size());
    // The pose must actually differ from the bind pose, or this check would be the test above.
    if (t > 0.3 && t < 3.0) {
      EXPECT_GT((x - c.bind_vertices()).cwiseAbs().maxCoeff(), 0.05) << "t = " << t;
    }
    EXPECT_LT((x - expected).cwiseAbs().maxCoeff(), 2e-5) << "t = " << t;
  }
}

TEST(CharacterSkinning, ClampHoldsTheEndsAndLoopRepeats) {
  Character clamp(test::character_asset());
  CharacterOptions loop_options;
  loop_options.wrap = TimeWrap::kLoop;
  Character loop(test::character_asset(), loop_options);
  VecX a, b;
  clamp.pose(-0.5, a);
  clamp.pose(0.0, b);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
  clamp.pose(10.0, a);
  clamp.pose(clamp.duration(), b);
  EXPECT_EQ((a - b).cwiseAbs().maxCoeff(), 0.0);
  loop.pose(1.25 + loop.duration(), a);
  loop.pose(1.25, b);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12);
  loop.pose(1.25 - 2.0 * loop.duration(), a);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(CharacterSkinning, PlacementMovesTheWholeBody) {
  CharacterOptions options;
  options.placement = Affine(Eigen::Translation3d(0.0, 1.024, 0.0));
  Character placed(test::character_asset(), options);
  Character plain(test::character_asset());
  VecX a, b;
  placed.pose(1.5, a);
  plain.pose(1.5, b);
  for (int v = 0; v < plain.vertex_count(); ++v)
    ASSERT_LT((seg(a, v) - seg(b, v) - Vec3(0.0, 1.024, 0.0)).norm(), 1e-12) << "vertex " << v;
}

TEST(CharacterSkinning, VelocitiesAreTheTimeDerivativeOfThePose) {
  Character c(test::character_asset());
  const double t = 1.01;  // between keys (they are 33 ms apart), so the motion is smooth around t
  VecX v, a, b;
  c.velocities(t, v);
  ASSERT_GT(v.cwiseAbs().maxCoeff(), 0.5);  // the body is moving fast here
  const double h = 2e-3;
  c.pose(t - h, a);
  c.pose(t + h, b);
  const VecX fd = (b - a) / (2.0 * h);
  EXPECT_LT((v - fd).cwiseAbs().maxCoeff(), 1e-3 * fd.cwiseAbs().maxCoeff());
}

TEST(CharacterSkinning, NormalsAreUnitAndPointOutOfTheChest) {
  Character c(test::character_asset());
  VecX x, n;
  c.pose(0.0, x);
  c.vertex_normals(x, n);
  int front = 0;  // the frontmost torso vertex (chest)
  for (int v = 0; v < c.mesh_vertex_begin()[1]; ++v)
    if (x[3 * v + 2] > x[3 * front + 2]) front = v;
  EXPECT_GT(seg(n, front).z(), 0.7);
  for (int v = 0; v < c.vertex_count(); ++v) ASSERT_NEAR(seg(n, v).norm(), 1.0, 1e-12) << "vertex " << v;
}

}  // namespace
}  // namespace kf
