#include "core/mesh_wire.h"

#include <assimp/scene.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

namespace kf {
namespace {

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_string(const aiString& s) { put_bytes(s.C_Str(), s.length); }
  void put_bytes(const void* p, size_t n) {
    put(static_cast<uint64_t>(n));
    out_.append(static_cast<const char*>(p), n);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <class T>
  T get() {
    T v;
    need(sizeof v);
    std::memcpy(&v, in_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  // A count of items that each take at least `item_bytes` of what is left (so a count cannot ask for
  // more memory than the bytes could describe).
  unsigned count(size_t item_bytes) {
    const auto n = get<uint32_t>();
    if (item_bytes > 0 && n > (in_.size() - at_) / item_bytes) throw MeshWireError("count beyond the data");
    return n;
  }
  void get_string(aiString& s) {
    const auto n = get<uint64_t>();
    if (n >= MAXLEN) throw MeshWireError("name too long");
    need(n);
    s.Set(std::string(in_.substr(at_, n)));
    at_ += n;
  }
  std::string get_bytes() {
    const auto n = get<uint64_t>();
    need(n);
    std::string s(in_.substr(at_, n));
    at_ += n;
    return s;
  }
  bool done() const { return at_ == in_.size(); }

 private:
  void need(uint64_t n) const {
    if (n > in_.size() - at_) throw MeshWireError("cut short");
  }
  std::string_view in_;
  size_t at_ = 0;
};

template <class K>
void put_keys(Writer& w, const K* keys, unsigned n) {
  w.put(static_cast<uint32_t>(n));
  for (unsigned k = 0; k < n; ++k) w.put(keys[k]);
}

template <class K>
K* get_keys(Reader& r, unsigned& n) {
  const unsigned count = r.count(sizeof(K));
  std::unique_ptr<K[]> keys(count ? new K[count] : nullptr);  // freed if the bytes are cut short
  for (unsigned k = 0; k < count; ++k) keys[k] = r.get<K>();
  n = count;
  return keys.release();
}

void put_mesh(Writer& w, const aiMesh& m) {
  w.put_string(m.mName);
  w.put(static_cast<uint32_t>(m.mNumVertices));
  for (unsigned v = 0; v < m.mNumVertices; ++v) w.put(m.mVertices[v]);
  w.put(static_cast<uint32_t>(m.mPrimitiveTypes));
  std::vector<const aiFace*> faces;
  for (unsigned f = 0; f < m.mNumFaces; ++f)
    if (m.mFaces[f].mNumIndices >= 3) faces.push_back(&m.mFaces[f]);
  w.put(static_cast<uint32_t>(faces.size()));
  for (const aiFace* f : faces) put_keys(w, f->mIndices, f->mNumIndices);
  w.put(static_cast<uint32_t>(m.mNumBones));
  for (unsigned b = 0; b < m.mNumBones; ++b) {
    const aiBone& bone = *m.mBones[b];
    w.put_string(bone.mName);
    w.put(bone.mOffsetMatrix);
    put_keys(w, bone.mWeights, bone.mNumWeights);
  }
}

aiMesh* get_mesh(Reader& r) {
  auto m = std::make_unique<aiMesh>();
  r.get_string(m->mName);
  m->mNumVertices = r.count(sizeof(aiVector3D));
  m->mVertices = new aiVector3D[m->mNumVertices];
  for (unsigned v = 0; v < m->mNumVertices; ++v) m->mVertices[v] = r.get<aiVector3D>();
  m->mPrimitiveTypes = r.get<uint32_t>();
  m->mNumFaces = r.count(4 * sizeof(uint32_t));  // a count and at least three corners each
  m->mFaces = new aiFace[m->mNumFaces];
  for (unsigned f = 0; f < m->mNumFaces; ++f) {
    aiFace& face = m->mFaces[f];
    face.mIndices = get_keys<unsigned>(r, face.mNumIndices);
    if (face.mNumIndices < 3) throw MeshWireError("face of fewer than 3 corners");
    for (unsigned k = 0; k < face.mNumIndices; ++k)
      if (face.mIndices[k] >= m->mNumVertices) throw MeshWireError("face index out of range");
  }
  const unsigned bones = r.count(sizeof(uint64_t) + sizeof(aiMatrix4x4) + sizeof(uint32_t));
  m->mBones = bones ? new aiBone*[bones]() : nullptr;
  while (m->mNumBones < bones) {
    aiBone* bone = m->mBones[m->mNumBones++] = new aiBone;  // counted first: freed with the mesh on a throw
    r.get_string(bone->mName);
    bone->mOffsetMatrix = r.get<aiMatrix4x4>();
    bone->mWeights = get_keys<aiVertexWeight>(r, bone->mNumWeights);
    for (unsigned k = 0; k < bone->mNumWeights; ++k)
      if (bone->mWeights[k].mVertexId >= m->mNumVertices) throw MeshWireError("bone weight's vertex out of range");
  }
  return m.release();
}

void put_animation(Writer& w, const aiAnimation& a) {
  w.put_string(a.mName);
  w.put(a.mDuration);
  w.put(a.mTicksPerSecond);
  w.put(static_cast<uint32_t>(a.mNumChannels));
  for (unsigned c = 0; c < a.mNumChannels; ++c) {
    const aiNodeAnim& ch = *a.mChannels[c];
    w.put_string(ch.mNodeName);
    put_keys(w, ch.mPositionKeys, ch.mNumPositionKeys);
    put_keys(w, ch.mRotationKeys, ch.mNumRotationKeys);
    put_keys(w, ch.mScalingKeys, ch.mNumScalingKeys);
  }
}

aiAnimation* get_animation(Reader& r) {
  auto a = std::make_unique<aiAnimation>();
  r.get_string(a->mName);
  a->mDuration = r.get<double>();
  a->mTicksPerSecond = r.get<double>();
  const unsigned channels = r.count(sizeof(uint64_t) + 3 * sizeof(uint32_t));
  a->mChannels = channels ? new aiNodeAnim*[channels]() : nullptr;
  while (a->mNumChannels < channels) {
    aiNodeAnim* ch = a->mChannels[a->mNumChannels++] = new aiNodeAnim;
    r.get_string(ch->mNodeName);
    ch->mPositionKeys = get_keys<aiVectorKey>(r, ch->mNumPositionKeys);
    ch->mRotationKeys = get_keys<aiQuatKey>(r, ch->mNumRotationKeys);
    ch->mScalingKeys = get_keys<aiVectorKey>(r, ch->mNumScalingKeys);
  }
  return a.release();
}

// Nodes depth first, each with its parent's index (earlier in the list).
void put_nodes(Writer& w, const aiNode* root) {
  std::vector<std::pair<const aiNode*, int32_t>> stack = {{root, -1}}, order;
  while (!stack.empty()) {
    const auto item = stack.back();
    stack.pop_back();
    order.push_back(item);
    for (unsigned c = item.first->mNumChildren; c-- > 0;)
      stack.push_back({item.first->mChildren[c], static_cast<int32_t>(order.size()) - 1});
  }
  w.put(static_cast<uint32_t>(order.size()));
  for (const auto& [n, parent] : order) {
    w.put_string(n->mName);
    w.put(parent);
    w.put(n->mTransformation);
    put_keys(w, n->mMeshes, n->mNumMeshes);
  }
}

aiNode* get_nodes(Reader& r, unsigned meshes) {
  const unsigned n = r.count(sizeof(uint64_t) + sizeof(int32_t) + sizeof(aiMatrix4x4) + sizeof(uint32_t));
  if (n == 0) throw MeshWireError("no root node");
  std::vector<std::unique_ptr<aiNode>> nodes;
  std::vector<std::vector<aiNode*>> children(n);
  std::vector<int32_t> parents(n);
  for (unsigned i = 0; i < n; ++i) {
    nodes.push_back(std::make_unique<aiNode>());
    aiNode& node = *nodes.back();
    r.get_string(node.mName);
    parents[i] = r.get<int32_t>();
    if ((i == 0) != (parents[i] < 0) || parents[i] >= static_cast<int32_t>(i)) throw MeshWireError("bad node parent");
    node.mTransformation = r.get<aiMatrix4x4>();
    node.mMeshes = get_keys<unsigned>(r, node.mNumMeshes);
    for (unsigned k = 0; k < node.mNumMeshes; ++k)
      if (node.mMeshes[k] >= meshes) throw MeshWireError("node's mesh out of range");
    if (i > 0) children[size_t(parents[i])].push_back(&node);
  }
  // Ownership passes to the parents (aiNode deletes its children), so only the root is released last.
  for (unsigned i = 0; i < n; ++i) {
    if (children[i].empty()) continue;
    aiNode& node = *nodes[i];
    node.mChildren = new aiNode*[children[i].size()];
    for (aiNode* c : children[i]) {
      c->mParent = &node;
      node.mChildren[node.mNumChildren++] = c;
    }
  }
  for (unsigned i = 1; i < n; ++i) nodes[i].release();
  return nodes[0].release();
}

void put_metadata(Writer& w, const aiMetadata* md) {
  std::vector<unsigned> kept;
  for (unsigned i = 0; md && i < md->mNumProperties; ++i)
    if (md->mValues[i].mData && md->mValues[i].mType <= AI_AISTRING) kept.push_back(i);
  w.put(static_cast<uint32_t>(kept.size()));
  for (unsigned i : kept) {
    const aiMetadataEntry& e = md->mValues[i];
    w.put_string(md->mKeys[i]);
    w.put(static_cast<int32_t>(e.mType));
    switch (e.mType) {
      case AI_BOOL: w.put(*static_cast<const bool*>(e.mData)); break;
      case AI_INT32: w.put(*static_cast<const int32_t*>(e.mData)); break;
      case AI_UINT64: w.put(*static_cast<const uint64_t*>(e.mData)); break;
      case AI_FLOAT: w.put(*static_cast<const float*>(e.mData)); break;
      case AI_DOUBLE: w.put(*static_cast<const double*>(e.mData)); break;
      default: w.put_string(*static_cast<const aiString*>(e.mData)); break;
    }
  }
}

aiMetadata* get_metadata(Reader& r) {
  const unsigned n = r.count(sizeof(uint64_t) + sizeof(int32_t) + 1);
  std::unique_ptr<aiMetadata> md(aiMetadata::Alloc(n));
  for (unsigned i = 0; i < n; ++i) {
    aiString key;
    r.get_string(key);
    if (key.length == 0) throw MeshWireError("empty metadata key");
    const std::string k = key.C_Str();
    switch (r.get<int32_t>()) {
      case AI_BOOL: md->Set(i, k, r.get<bool>()); break;
      case AI_INT32: md->Set(i, k, r.get<int32_t>()); break;
      case AI_UINT64: md->Set(i, k, r.get<uint64_t>()); break;
      case AI_FLOAT: md->Set(i, k, r.get<float>()); break;
      case AI_DOUBLE: md->Set(i, k, r.get<double>()); break;
      case AI_AISTRING: {
        aiString v;
        r.get_string(v);
        md->Set(i, k, v);
        break;
      }
      default: throw MeshWireError("bad metadata type");
    }
  }
  return md.release();
}

}  // namespace

std::string scene_to_bytes(const aiScene& scene) {
  Writer w;
  w.put(static_cast<uint32_t>(scene.mFlags));
  w.put(static_cast<uint32_t>(scene.mNumMeshes));
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) put_mesh(w, *scene.mMeshes[m]);
  w.put(static_cast<uint32_t>(scene.mNumAnimations));
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) put_animation(w, *scene.mAnimations[a]);
  put_nodes(w, scene.mRootNode);
  put_metadata(w, scene.mMetaData);
  return w.take();
}

std::unique_ptr<aiScene> scene_from_bytes(std::string_view bytes) {
  Reader r(bytes);
  auto scene = std::make_unique<aiScene>();
  scene->mFlags = r.get<uint32_t>();
  const unsigned meshes = r.count(sizeof(uint64_t) + 3 * sizeof(uint32_t));
  // Arrays are counted full from the start (null entries): the scene frees whatever was built on a throw.
  scene->mMeshes = meshes ? new aiMesh*[meshes]() : nullptr;
  scene->mNumMeshes = meshes;
  for (unsigned m = 0; m < meshes; ++m) scene->mMeshes[m] = get_mesh(r);
  const unsigned animations = r.count(sizeof(uint64_t) + 2 * sizeof(double) + sizeof(uint32_t));
  scene->mAnimations = animations ? new aiAnimation*[animations]() : nullptr;
  scene->mNumAnimations = animations;
  for (unsigned a = 0; a < animations; ++a) scene->mAnimations[a] = get_animation(r);
  scene->mRootNode = get_nodes(r, scene->mNumMeshes);
  scene->mMetaData = get_metadata(r);
  if (!r.done()) throw MeshWireError("bytes after the scene");
  return scene;
}

}  // namespace kf
