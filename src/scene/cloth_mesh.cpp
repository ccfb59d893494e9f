#include "scene/cloth_mesh.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/file_name.h"
#include "core/mesh_import.h"

namespace kf {

std::vector<int> ClothMesh::triangles() const {
  std::vector<int> out;
  for (const auto& f : faces)
    for (size_t k = 1; k + 1 < f.size(); ++k) out.insert(out.end(), {f[0], f[k], f[k + 1]});
  return out;
}

namespace {

constexpr int kMaxCorners = 1000;
constexpr size_t kMaxGroups = 1000;  // named sets kept from one file

// The polygon without repeated consecutive corners; fanned into triangles beyond 4 corners (a quad stays a
// quad: a grid's quads give its shear springs on both diagonals).
void add_face(std::vector<int> f, std::vector<std::vector<int>>& faces) {
  std::vector<int> g;
  for (size_t k = 0; k < f.size(); ++k)
    if (f[k] != f[(k + 1) % f.size()]) g.push_back(f[k]);
  std::vector<int> sorted = g;
  std::sort(sorted.begin(), sorted.end());
  if (g.size() < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return;
  if (g.size() <= 4) {
    faces.push_back(std::move(g));
    return;
  }
  for (size_t k = 1; k + 1 < g.size(); ++k) faces.push_back({g[0], g[k], g[k + 1]});
}

// Keeps the vertices the faces use, in their order, and renumbers the faces and the named sets.
ClothMesh compacted(const std::string& file, const std::vector<Vec3>& all, std::vector<std::vector<int>> faces,
                    std::map<std::string, std::vector<int>> groups = {}) {
  std::vector<int> index(all.size(), -1);
  for (const auto& f : faces)
    for (int v : f) index[size_t(v)] = 0;
  ClothMesh m;
  m.file = file;
  for (size_t v = 0; v < all.size(); ++v)
    if (index[v] == 0) {
      index[v] = int(m.vertices.size());
      m.vertices.push_back(all[v]);
    }
  for (auto& f : faces)
    for (int& v : f) v = index[size_t(v)];
  m.faces = std::move(faces);
  for (auto& [name, set] : groups) {
    std::vector<int> kept;
    for (int v : set)
      if (index[size_t(v)] >= 0) kept.push_back(index[size_t(v)]);
    std::sort(kept.begin(), kept.end());
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
    if (!kept.empty()) m.groups[name] = std::move(kept);
  }
  return m;
}

// The corners of an OBJ face line after "f", as 0-based vertex indices (a, a/t, a//n, a/t/n; negative: from
// the end of the `vertices` read so far).
template <class Fail>
std::vector<int> read_face_corners(std::istringstream& ls, long vertices, const Fail& fail) {
  std::vector<int> f;
  std::string corner;
  while (ls >> corner) {
    long i = 0;
    try {
      size_t used = 0;
      i = std::stol(corner, &used);
      if (used < corner.size() && corner[used] != '/') fail("bad face corner \"" + corner + "\"");
    } catch (const std::logic_error&) {
      fail("bad face corner \"" + corner + "\"");
    }
    if (i < 0) i += vertices + 1;
    if (i < 1 || i > vertices) fail("face corner " + corner + " names no vertex read so far");
    if (f.size() >= size_t(kMaxCorners)) fail("a face with more than " + std::to_string(kMaxCorners) + " corners");
    f.push_back(int(i - 1));
  }
  return f;
}

// OBJ: "v x y z", "f a b c ..." (a, a/t, a//n, a/t/n; negative: from the end), "o"/"g" names.
ClothMesh read_obj(const std::filesystem::path& path, const std::string& name) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open the cloth mesh");
  std::vector<Vec3> vertices;
  std::vector<std::vector<int>> faces;
  std::vector<std::string> names;
  std::map<std::string, std::vector<int>> groups;  // by "o" and "g" name: the vertices of their faces
  std::string object, group, line;
  bool named_found = name.empty();
  long line_no = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(file + ": line " + std::to_string(line_no) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag)) continue;
    if (tag == "v") {
      Vec3 p;
      if (!(ls >> p.x() >> p.y() >> p.z()) || !p.allFinite() || p.cwiseAbs().maxCoeff() > 1e9)
        fail("expected \"v x y z\" with finite coordinates");
      if (int(vertices.size()) >= kMaxClothMeshVertices)
        fail("more than " + std::to_string(kMaxClothMeshVertices) + " vertices");
      vertices.push_back(p);
    } else if (tag == "o" || tag == "g") {
      std::string n;
      std::getline(ls >> std::ws, n);
      while (!n.empty() && (n.back() == '\r' || n.back() == ' ')) n.pop_back();
      (tag == "o" ? object : group) = n;
      if (tag == "o") group.clear();
      if (!n.empty() && std::find(names.begin(), names.end(), n) == names.end() && names.size() < 50) names.push_back(n);
    } else if (tag == "f") {
      const bool wanted = name.empty() || object == name || group == name;
      named_found = named_found || wanted;
      std::vector<int> f = read_face_corners(ls, long(vertices.size()), fail);
      if (f.size() < 3) fail("expected a face of at least 3 corners");
      if (!wanted) continue;
      for (const std::string* n : {&object, &group})
        if (!n->empty() && (groups.count(*n) || groups.size() < kMaxGroups)) {
          auto& set = groups[*n];
          set.insert(set.end(), f.begin(), f.end());
        }
      add_face(std::move(f), faces);
    }
  }
  if (!named_found) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + ("\"" + n + "\"");
    throw InputError(file + ": no object or group named \"" + name + "\" (the file has " +
                     (list.empty() ? std::string("none") : list) + ")");
  }
  return compacted(file, vertices, std::move(faces), std::move(groups));
}

// Any other format, through assimp in a child process (core/mesh_import.h: its crashes, non-regular or
// oversized referenced files and non-finite vertices are InputErrors naming the file): the named mesh (or
// the only one), corners at equal positions welded (an exporter splits a vertex where its normals or
// texture coordinates differ).
ClothMesh read_with_assimp(const std::filesystem::path& path, const std::string& name) {
  const std::string file = printable(path.string());
  MeshImportOptions options;
  options.steps = aiProcess_JoinIdenticalVertices;
  const std::unique_ptr<aiScene> scene = import_mesh_file(path, options);
  std::vector<const aiMesh*> matches;
  std::string list;
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh* m = scene->mMeshes[k];
    if (!(m->mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON))) continue;
    const std::string n = m->mName.C_Str();
    list += (list.empty() ? "" : ", ") + ("\"" + printable(n) + "\"");
    if (name.empty() || n == name) matches.push_back(m);
  }
  if (matches.size() != 1) {
    const std::string what = name.empty() ? "expected one mesh with faces or cloth.mesh.name"
                                          : "no mesh named \"" + printable(name) + "\"";
    throw InputError(file + ": " + what + " (the file has " + (list.empty() ? std::string("none") : list) + ")");
  }
  const aiMesh* m = matches[0];
  if (m->mNumVertices > unsigned(kMaxClothMeshVertices))
    throw InputError(file + ": more than " + std::to_string(kMaxClothMeshVertices) + " vertices");
  std::vector<Vec3> all;
  std::vector<int> weld(m->mNumVertices);
  std::map<std::array<double, 3>, int> seen;
  for (unsigned v = 0; v < m->mNumVertices; ++v) {
    const Vec3 p(m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z);
    if (!p.allFinite()) throw InputError(file + ": vertex " + std::to_string(v) + " is not finite");
    auto [it, fresh] = seen.insert({{p.x(), p.y(), p.z()}, int(all.size())});
    if (fresh) all.push_back(p);
    weld[v] = it->second;
  }
  std::vector<std::vector<int>> faces;
  for (unsigned k = 0; k < m->mNumFaces; ++k) {
    const aiFace& face = m->mFaces[k];
    if (face.mNumIndices < 3 || face.mNumIndices > unsigned(kMaxCorners)) continue;
    std::vector<int> f;
    for (unsigned c = 0; c < face.mNumIndices; ++c) {
      if (face.mIndices[c] >= m->mNumVertices) throw InputError(file + ": a face names a vertex the mesh lacks");
      f.push_back(weld[face.mIndices[c]]);
    }
    add_face(std::move(f), faces);
  }
  return compacted(file, all, std::move(faces));
}

std::string lower_extension(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

}  // namespace

ClothMesh read_cloth_mesh(const std::filesystem::path& file, const std::string& name) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string() + ": cloth mesh not found (expected a regular file assimp can read: .obj, .ply, "
                                     ".gltf, .dae, ...)");
  const std::uintmax_t bytes = std::filesystem::file_size(file, ec);
  if (ec || bytes > kMaxClothMeshBytes) throw InputError(file.string() + ": cloth mesh larger than 1 GiB");
  ClothMesh m = lower_extension(file) == ".obj" ? read_obj(file, name) : read_with_assimp(file, name);
  if (m.faces.empty()) throw InputError(file.string() + ": the cloth mesh has no faces");
  return m;
}

}  // namespace kf
