// keyframe export carries the scene's colliders: each shape read back from the exported files lies on its
// surface, and the rest OBJs say what their vertices are.
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <fstream>
#include <map>

#include "render/export/export_run.h"
#include "sim/cloth/collider.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

// The synthetic sheet with one collider of every shape.
fs::path cloth_run_with_colliders(const fs::path& dir) {
  const auto run = testing::make_cloth_run(dir, 8);
  testing::write_text(run / "scene.json", R"({"time": {"frames": 5}, "cloth": {"nx": 8, "ny": 8, "colliders": [
      {"type": "sphere", "center": [0.2, 0.4, 0.1], "radius": 0.3},
      {"type": "torus", "center": [-0.4, 1.5, -0.3], "axis": [0, 0, 1], "radius": 0.25, "tube_radius": 0.03},
      {"type": "capsule", "a": [-1, 0.2, 0.5], "b": [1, 0.2, 0.5], "radius": 0.05},
      {"type": "ground", "center": [0, -0.1, 0]},
      {"type": "box", "center": [0.5, -0.3, 0.2], "size": [0.6, 0.2, 0.4], "u_axis": [0.8, 0, 0.6], "radius": 0.05},
      {"type": "rectangle", "center": [-0.5, 0.1, 0], "u_axis": [1, 0, 0], "v_axis": [0, 0.6, 0.8], "width": 0.5,
       "height": 0.3}]}, "objectives": []})");
  return run;
}

// Every mesh assimp finds in `file`: its vertices by mesh name.
std::map<std::string, std::vector<Vec3>> read_meshes(const fs::path& file) {
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile(file.string(), aiProcess_JoinIdenticalVertices);
  EXPECT_NE(s, nullptr) << file << ": " << importer.GetErrorString();
  std::map<std::string, std::vector<Vec3>> out;
  if (s)
    for (unsigned k = 0; k < s->mNumMeshes; ++k) {
      const aiMesh* m = s->mMeshes[k];
      auto& v = out[m->mName.C_Str()];
      for (unsigned i = 0; i < m->mNumVertices; ++i) v.emplace_back(m->mVertices[i].x, m->mVertices[i].y, m->mVertices[i].z);
    }
  return out;
}

// Largest distance of `points` from each surface (0 for points on it); at least 20 points each.
void expect_on_colliders(std::map<std::string, std::vector<Vec3>> meshes) {
  auto worst = [](const std::vector<Vec3>& pts, auto&& dist) {
    double w = 0;
    for (const Vec3& p : pts) w = std::max(w, std::abs(dist(p)));
    return w;
  };
  for (const char* name : {"collider_0_sphere", "collider_1_torus", "collider_2_capsule", "collider_3_ground"})
    EXPECT_GE(meshes[name].size(), 4u) << name;
  EXPECT_GE(meshes["collider_0_sphere"].size(), 20u);
  EXPECT_LT(worst(meshes["collider_0_sphere"], [](const Vec3& p) { return (p - Vec3(0.2, 0.4, 0.1)).norm() - 0.3; }), 1e-5);
  EXPECT_LT(worst(meshes["collider_1_torus"],
                  [](const Vec3& p) {
                    const Vec3 q = p - Vec3(-0.4, 1.5, -0.3);  // axis z: the ring lies in the xy plane
                    return std::hypot(std::hypot(q.x(), q.y()) - 0.25, q.z()) - 0.03;
                  }),
            1e-5);
  EXPECT_LT(worst(meshes["collider_2_capsule"],
                  [](const Vec3& p) {
                    const double x = std::clamp(p.x(), -1.0, 1.0);
                    return (p - Vec3(x, 0.2, 0.5)).norm() - 0.05;
                  }),
            1e-5);
  const auto& ground = meshes["collider_3_ground"];
  EXPECT_LT(worst(ground, [](const Vec3& p) { return p.y() + 0.1; }), 1e-6);
  // The floor reaches past the sheet (1.5 m wide) on every side.
  double lo = 1e9, hi = -1e9;
  for (const Vec3& p : ground) lo = std::min(lo, p.x()), hi = std::max(hi, p.x());
  EXPECT_LT(lo, -1.0);
  EXPECT_GT(hi, 1.0);
  EXPECT_EQ(meshes["cloth"].size(), 64u);
  // The box and the rectangle: every vertex on the surface their collider pushes out of.
  const BoxCollider box(BoxShape{Vec3(0.5, -0.3, 0.2), Vec3(0.6, 0.2, 0.4), Vec3(0.8, 0, 0.6), Vec3::UnitY(), 0.05},
                        0.01, 1, 0);
  const BoxCollider panel(RectangleShape{Vec3(-0.5, 0.1, 0), Vec3::UnitX(), Vec3(0, 0.6, 0.8), 0.5, 0.3}, 0.01, 1, 0);
  const auto phi = [](const BoxCollider& c) {
    return [&c](const Vec3& p) {
      double d;
      Vec3 n;
      Mat3 dn;
      c.distance(p, d, n, dn);
      return d;
    };
  };
  EXPECT_GE(meshes["collider_4_box"].size(), 20u);
  EXPECT_LT(worst(meshes["collider_4_box"], phi(box)), 1e-5);
  EXPECT_GE(meshes["collider_5_rectangle"].size(), 4u);
  EXPECT_LT(worst(meshes["collider_5_rectangle"], phi(panel)), 1e-6);
}

TEST(ColliderExport, ObjGltfAndPointCacheCarryEveryColliderShape) {
  testing::TempDir tmp;
  const auto run = cloth_run_with_colliders(tmp.path() / "cloth");
  ExportRequest r;
  r.run_dir = run;
  r.format = "obj";
  export_run(r);
  {
    SCOPED_TRACE("obj");
    expect_on_colliders(read_meshes(run / "export/frame_0003.obj"));
  }
  r.format = "gltf2";
  export_run(r);
  {
    SCOPED_TRACE("gltf2");
    expect_on_colliders(read_meshes(run / "export/cloth.gltf"));
  }
  r.format = "pc2";
  const auto files = export_run(r);
  EXPECT_EQ(files.size(), 14u);  // the cloth and six colliders: .obj and .pc2 each
  {
    SCOPED_TRACE("rest obj");
    std::map<std::string, std::vector<Vec3>> all;  // one object per rest OBJ
    for (const char* name : {"cloth", "collider_0_sphere", "collider_1_torus", "collider_2_capsule", "collider_3_ground",
                             "collider_4_box", "collider_5_rectangle"})
      all.merge(read_meshes(run / "export" / (std::string(name) + ".obj")));
    expect_on_colliders(all);
  }
  std::ifstream obj(run / "export/collider_1_torus.obj");
  std::string header;
  std::getline(obj, header);
  EXPECT_NE(header.find("a static torus collider"), std::string::npos) << header;
}

TEST(ColliderExport, AgentRestObjSaysHowManyVerticesEachAgentHas) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");  // 40 agents
  ExportRequest r;
  r.run_dir = run;
  r.format = "pc2";
  export_run(r);
  std::ifstream obj(run / "export/agents.obj");
  std::string header;
  std::getline(obj, header);
  int vertices = 0;
  for (std::string line; std::getline(obj, line);) vertices += line.rfind("v ", 0) == 0;
  ASSERT_EQ(vertices % 40, 0);
  const int per = vertices / 40;
  EXPECT_EQ(header.find("vertex i is particle i"), std::string::npos) << header;
  EXPECT_NE(header.find("agent k is vertices " + std::to_string(per) + "k.." + std::to_string(per) + "k+" +
                        std::to_string(per - 1)),
            std::string::npos)
      << header;
  // The cloth's rest OBJ keeps its one vertex per particle.
  const auto cloth = testing::make_cloth_run(tmp.path() / "cloth", 8);
  r.run_dir = cloth;
  export_run(r);
  std::ifstream cloth_obj(cloth / "export/cloth.obj");
  std::getline(cloth_obj, header);
  EXPECT_NE(header.find("vertex i is particle i"), std::string::npos) << header;
}

}  // namespace
}  // namespace kf::render
