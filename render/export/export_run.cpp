#include "render/export/export_run.h"

#include <Eigen/Geometry>
#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "core/atomic_file.h"
#include "core/dir_lock.h"
#include "core/error.h"
#include "core/overloaded.h"
#include "render/export/animated_gltf.h"
#include "render/export/checked_io.h"
#include "render/export/point_cache.h"
#include "render/frame_renderer.h"
#include "render/geometry/system_geometry.h"

namespace kf::render {

namespace fs = std::filesystem;

namespace {

enum class Layout { kPerFrame, kAnimatedGltf, kPointCache };
struct Format {
  const char* name;       // --format
  const char* assimp_id;  // assimp's exporter id (per-frame files)
  const char* extension;
  Layout layout;
};
constexpr Format kFormats[] = {
    {"gltf2", "", ".gltf", Layout::kAnimatedGltf},
    {"pc2", "", ".pc2", Layout::kPointCache},
    {"obj", "obj", ".obj", Layout::kPerFrame},
    {"ply", "plyb", ".ply", Layout::kPerFrame},
};

// A named triangle mesh with per-vertex normals, single precision like the file formats.
struct ExportMesh {
  std::string name;
  std::vector<float> p, n;       // 3V each, metres / unit
  std::vector<uint32_t> indices;  // 3T
  Vec3 color;
  std::string vertices;  // what the vertices are, for the rest OBJ's header
};

aiMesh* to_ai_mesh(const ExportMesh& m, unsigned material) {
  auto* out = new aiMesh;
  out->mName = m.name;
  out->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out->mMaterialIndex = material;
  out->mNumVertices = unsigned(m.p.size() / 3);
  out->mVertices = new aiVector3D[out->mNumVertices];
  out->mNormals = new aiVector3D[out->mNumVertices];
  for (unsigned i = 0; i < out->mNumVertices; ++i) {
    out->mVertices[i] = aiVector3D(m.p[3 * i], m.p[3 * i + 1], m.p[3 * i + 2]);
    out->mNormals[i] = aiVector3D(m.n[3 * i], m.n[3 * i + 1], m.n[3 * i + 2]);
  }
  out->mNumFaces = unsigned(m.indices.size() / 3);
  out->mFaces = new aiFace[out->mNumFaces];
  for (unsigned f = 0; f < out->mNumFaces; ++f) {
    out->mFaces[f].mNumIndices = 3;
    out->mFaces[f].mIndices = new unsigned[3]{m.indices[3 * f], m.indices[3 * f + 1], m.indices[3 * f + 2]};
  }
  return out;
}

aiMaterial* to_ai_material(const std::string& name, const Vec3& c) {
  auto* mat = new aiMaterial;
  const aiString n(name);
  mat->AddProperty(&n, AI_MATKEY_NAME);
  const aiColor3D diffuse(float(c.x()), float(c.y()), float(c.z()));
  mat->AddProperty(&diffuse, 1, AI_MATKEY_COLOR_DIFFUSE);
  const aiColor4D base(float(c.x()), float(c.y()), float(c.z()), 1.0f);
  mat->AddProperty(&base, 1, AI_MATKEY_BASE_COLOR);
  return mat;
}

// One frame as a scene: a root with one child node per object, so cape and body stay separate objects.
std::unique_ptr<aiScene> make_scene(const std::vector<ExportMesh>& objects) {
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode("keyframe");
  const unsigned n = unsigned(objects.size());
  scene->mNumMeshes = scene->mNumMaterials = n;
  scene->mMeshes = new aiMesh*[n];
  scene->mMaterials = new aiMaterial*[n];
  scene->mRootNode->mNumChildren = n;
  scene->mRootNode->mChildren = new aiNode*[n];
  for (unsigned k = 0; k < n; ++k) {
    auto* node = new aiNode(objects[k].name);
    node->mParent = scene->mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{k};
    scene->mRootNode->mChildren[k] = node;
    scene->mMaterials[k] = to_ai_material(objects[k].name, objects[k].color);
    scene->mMeshes[k] = to_ai_mesh(objects[k], k);
  }
  return scene;
}

ExportMesh from_render_mesh(const std::string& name, const Mesh& m, const Vec3& color) {
  ExportMesh e{name, {}, {}, m.indices, color};
  for (const Vertex& v : m.vertices) {
    e.p.insert(e.p.end(), v.p, v.p + 3);
    e.n.insert(e.n.end(), v.n, v.n + 3);
  }
  return e;
}

// The cloth at one frame as a triangle mesh with area-weighted vertex normals: the grid's quads split along
// one diagonal, or the mesh's faces (mesh.triangles()).
ExportMesh cloth_mesh(const RunData& run, const ClothSpec& cloth, int frame) {
  const VecX& x = run.trajectory.x[size_t(frame)];
  const int p = cloth.particles();
  ExportMesh e{"cloth", {}, {}, {}, run.scene.render.cloth_front, "vertex i is particle i"};
  if (cloth.mesh) {
    for (int v : cloth.mesh->triangles()) e.indices.push_back(uint32_t(v));
  } else {
    const int nx = cloth.nx, ny = cloth.ny;
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        const uint32_t a = uint32_t(j * nx + i), b = a + 1, c = a + uint32_t(nx) + 1, d = a + uint32_t(nx);
        e.indices.insert(e.indices.end(), {a, b, c, a, c, d});
      }
  }
  std::vector<Vec3> normal(size_t(p), Vec3::Zero());
  for (size_t t = 0; t + 2 < e.indices.size(); t += 3) {
    const int a = int(e.indices[t]), b = int(e.indices[t + 1]), c = int(e.indices[t + 2]);
    const Vec3 n = (seg(x, b) - seg(x, a)).cross(seg(x, c) - seg(x, a));
    for (int v : {a, b, c}) normal[size_t(v)] += n;
  }
  for (int i = 0; i < p; ++i) {
    const Vec3 q = seg(x, i), n = normal[size_t(i)].norm() > 1e-30 ? normal[size_t(i)].normalized() : Vec3::UnitY();
    e.p.insert(e.p.end(), {float(q.x()), float(q.y()), float(q.z())});
    e.n.insert(e.n.end(), {float(n.x()), float(n.y()), float(n.z())});
  }
  return e;
}

// The flock's agents as drawn: an arrowhead of the same vertex count per agent, in agent order.
ExportMesh agents_mesh(const RunData& run, int frame, const Bounds& bounds, FrameGeometry& g) {
  build_frame_geometry(run.scene, run.trajectory, frame, bounds, g);
  ExportMesh e = from_render_mesh("agents", g.objects, run.scene.render.agent_color);
  const size_t per = g.objects.vertices.size() / size_t(std::max(run.trajectory.particles, 1));
  e.vertices = "agent k is vertices " + std::to_string(per) + "k.." + std::to_string(per) + "k+" +
               std::to_string(per - 1) + " (its arrowhead, " + std::to_string(per / 3) + " flat triangles)";
  return e;
}

// The cloth's colliders (they do not move): collider_K_SHAPE, a ground as a square around the scene.
void add_collider_meshes(const RunData& run, const Bounds& bounds, std::vector<ExportMesh>& out) {
  if (!run.scene.cloth) return;
  const auto& colliders = run.scene.cloth->colliders;
  const Vec3& color = run.scene.render.collider_color;
  for (size_t k = 0; k < colliders.size(); ++k) {
    const ColliderShape& shape = colliders[k].shape;
    Mesh m;
    if (const auto* ground = std::get_if<GroundShape>(&shape)) add_ground_square(m, *ground, bounds, color);
    else add_collider(m, shape, color);
    const std::string kind = std::visit([](const auto& s) { return std::string(std::decay_t<decltype(s)>::kName); }, shape);
    ExportMesh e = from_render_mesh("collider_" + std::to_string(k) + "_" + kind, m, color);
    e.vertices = "a static " + kind + " collider (the same every frame)";
    out.push_back(std::move(e));
  }
}

// The frame's meshes: the particles as a surface (cloth grid or agent arrowheads), the bodies and the
// colliders.
std::vector<ExportMesh> frame_meshes(const RunData& run, int frame, const Bounds& bounds, FrameGeometry& g) {
  std::vector<ExportMesh> out;
  const RenderSpec& rs = run.scene.render;
  visit_system(run.scene, Overloaded{
                              [&](const ClothSpec& cloth) { out.push_back(cloth_mesh(run, cloth, frame)); },
                              [&](const FlockSpec&) { out.push_back(agents_mesh(run, frame, bounds, g)); },
                          });
  if (run.meshes) {
    for (int k = 0; k < int(run.meshes->meshes.size()); ++k) {
      Mesh body;
      add_body_mesh(*run.meshes, frame, k, rs.body_color, body);
      const std::string& name = run.meshes->meshes[size_t(k)].name;
      out.push_back(from_render_mesh(name, body, rs.body_color));
      out.back().vertices = "vertex i is vertex i of mesh \"" + name + "\" in meshes.bin";
    }
  }
  add_collider_meshes(run, bounds, out);
  return out;
}

// Every object over frames [begin, end): its triangles (the same every frame) and per-frame vertices.
std::vector<MovingMesh> moving_meshes(const fs::path& run_dir, const RunData& run, int begin, int end,
                                      const Bounds& bounds, FrameGeometry& g) {
  std::vector<MovingMesh> out;
  for (int f = begin; f < end; ++f) {
    std::vector<ExportMesh> frame = frame_meshes(run, f, bounds, g);
    if (out.empty())
      for (const ExportMesh& e : frame) out.push_back({e.name, e.color, e.indices, {}, {}, e.vertices});
    for (size_t k = 0; k < frame.size(); ++k) {
      if (k >= out.size() || frame[k].indices != out[k].indices)
        throw InputError(run_dir.string() + ": frame " + std::to_string(f) + ": the meshes change between frames; export per frame (obj, ply)");
      out[k].positions.push_back(std::move(frame[k].p));
      out[k].normals.push_back(std::move(frame[k].n));
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> export_format_names() {
  std::vector<std::string> names;
  for (const auto& f : kFormats) names.push_back(f.name);
  return names;
}

namespace {

const Format& find_format(const std::string& name) {
  for (const auto& f : kFormats)
    if (name == f.name) return f;
  std::string names;
  for (const auto& n : export_format_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError("unknown export format \"" + name + "\" (expected one of: " + names + ")");
}

// The end of the frame range (one past the last frame), after checking the range against the run.
int checked_frame_end(const ExportRequest& r, const RunData& run) {
  const int F = run.trajectory.frames();
  const int begin = r.frame_begin, end = r.frame_end < 0 ? F : r.frame_end;
  if (begin < 0 || begin >= F || end <= begin || end > F)
    throw InputError("frames " + std::to_string(begin) + ":" + std::to_string(r.frame_end) + " out of range: " +
                     r.run_dir.string() + " has frames 0.." + std::to_string(F - 1) + " (A:B exports A..B-1)");
  return end;
}

void check_exporter_available(const Assimp::Exporter& exporter, const Format& format) {
  if (format.layout != Layout::kPerFrame) return;
  bool available = false;
  for (size_t k = 0; k < exporter.GetExportFormatCount(); ++k)
    available = available || std::string(exporter.GetExportFormatDescription(k)->id) == format.assimp_id;
  if (!available) throw InputError(std::string("this assimp has no \"") + format.assimp_id + "\" exporter");
}

// What one export writes and where: files go to `partial` and are named after `dir` in messages.
struct ExportJob {
  const Format& format;
  const RunData& run;
  int begin, end;
  fs::path dir, partial;
  Bounds bounds;
  FrameGeometry g;
};

void write_per_frame(ExportJob& job, Assimp::Exporter& exporter, const CheckedIOSystem& io) {
  char name[64];
  for (int f = job.begin; f < job.end; ++f) {
    std::snprintf(name, sizeof name, "frame_%04d", f);
    const std::string file = name + std::string(job.format.extension);
    if (exporter.Export(make_scene(frame_meshes(job.run, f, job.bounds, job.g)).get(), job.format.assimp_id,
                        (job.partial / file).string()) != aiReturn_SUCCESS)
      throw OutputError((job.dir / file).string() + ": export failed (" + exporter.GetErrorString() + ")");
    if (!io.first_error().empty()) throw OutputError(io.first_error());
    if (std::error_code missing; !fs::is_regular_file(job.partial / file, missing))
      throw OutputError((job.dir / file).string() + ": export failed (assimp wrote no file)");
  }
}

void write_moving(ExportJob& job, const fs::path& run_dir) {
  const std::vector<MovingMesh> objects = moving_meshes(run_dir, job.run, job.begin, job.end, job.bounds, job.g);
  const std::string& scene = job.run.scene.name;
  if (job.format.layout == Layout::kAnimatedGltf) {
    write_animated_gltf(job.partial / (scene + ".gltf"), job.partial / (scene + ".bin"), objects,
                        job.run.scene.time.fps);
    return;
  }
  for (const MovingMesh& m : objects) {
    write_rest_obj(job.partial / (m.name + ".obj"), m);
    write_pc2(job.partial / (m.name + ".pc2"), m, job.begin);
  }
}

// Writes every file into the partial folder, or removes it and rethrows (naming the export folder).
void write_partial(ExportJob& job, Assimp::Exporter& exporter, const CheckedIOSystem& io, const fs::path& run_dir) {
  std::error_code ec;
  try {
    if (job.format.layout == Layout::kPerFrame)
      write_per_frame(job, exporter, io);
    else
      write_moving(job, run_dir);
  } catch (const OutputError& e) {
    fs::remove_all(job.partial, ec);
    std::string message = e.what();  // name the export folder, not its hidden partial copy
    if (message.rfind(job.partial.string(), 0) == 0) message.replace(0, job.partial.string().size(), job.dir.string());
    throw OutputError(message);
  } catch (...) {
    fs::remove_all(job.partial, ec);
    throw;
  }
}

// Every file was written: only now do they replace what an earlier export left.
std::vector<fs::path> move_into_place(const fs::path& partial, const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> written;
  for (const auto& e : fs::directory_iterator(partial)) {
    const fs::path target = dir / e.path().filename();
    fs::rename(e.path(), target, ec);
    if (ec) throw OutputError(target.string() + ": cannot write (" + ec.message() + ")");
    written.push_back(target);
  }
  fs::remove_all(partial, ec);
  std::sort(written.begin(), written.end());
  return written;
}

}  // namespace

std::vector<fs::path> export_run(const ExportRequest& r) {
  const Format& format = find_format(r.format);
  const RunData run = load_run(r.run_dir);
  const int end = checked_frame_end(r, run);
  Assimp::Exporter exporter;
  auto* io = new CheckedIOSystem;  // the exporter owns it
  exporter.SetIOHandler(io);
  check_exporter_available(exporter, format);

  const DirLock lock(r.run_dir, DirLock::Mode::kShared);  // no optimisation replaces the run meanwhile
  const fs::path dir = r.run_dir / "export";
  const fs::path partial = dir / (".partial_" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(partial, ec);
  ensure_directory(partial);
  ExportJob job{format, run, r.frame_begin, end, dir, partial,
                scene_bounds(run.scene, run.trajectory, run.meshes ? &*run.meshes : nullptr), {}};
  write_partial(job, exporter, *io, r.run_dir);
  return move_into_place(partial, dir);
}

}  // namespace kf::render
