#include "core/mesh_import.h"

#include <assimp/DefaultIOSystem.h>
#include <assimp/scene.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <assimp/Importer.hpp>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <string>

#include "core/error.h"
#include "core/file_name.h"
#include "core/mesh_wire.h"

// Present only under a sanitizer: the child clears it so that its crash is not reported as the parent's
// (a fuzzer's death callback would save the input as a finding of the parent).
extern "C" void __sanitizer_set_death_callback(void (*)(void)) __attribute__((weak));

namespace kf {
namespace {

// Empty when `path` is a regular file under the cap; otherwise what is wrong with it.
std::string file_problem(const char* path) {
  struct stat st {};
  if (::stat(path, &st) != 0) return errno == ENOENT || errno == ENOTDIR ? "not found" : std::strerror(errno);
  if (!S_ISREG(st.st_mode)) return "not a regular file";
  if (std::uintmax_t(st.st_size) > kMaxMeshFileBytes) return "larger than the 1 GiB a mesh file may be";
  return "";
}

// Whether nothing is at `path` (no entry, or a path through a non-directory), as opposed to something
// that is there but refused.
bool absent(const char* path) {
  struct stat st {};
  return ::stat(path, &st) != 0 && (errno == ENOENT || errno == ENOTDIR);
}

// assimp's file access, refusing anything but regular files under the cap (a FIFO would block the read,
// /dev/zero would never end) and any writing; remembers the first file it refused. A file that does not
// exist reads as absent, as with assimp's own IOSystem: importers probe for optional companions (an SMD's
// <name>_animation.txt) and go on without them; one they need fails in assimp with its own message.
class RegularFilesOnly : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* file) const override {
    struct stat st {};
    return ::stat(file, &st) == 0;  // not by opening it, which blocks on a FIFO
  }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    const bool writing = std::strpbrk(mode, "wa+") != nullptr;
    if (!writing && absent(file)) return nullptr;
    std::string problem = writing ? "opened for writing" : file_problem(file);
    if (problem.empty()) return Assimp::DefaultIOSystem::Open(file, mode);
    if (refused.empty()) refused = "'" + printable(file) + "' (a file it reads): " + problem;
    return nullptr;
  }
  std::string refused;
};

bool finite(const aiVector3D& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const aiQuaternion& q) { return finite(aiVector3D(q.x, q.y, q.z)) && std::isfinite(q.w); }
bool finite(const aiMatrix4x4& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(m[r][c])) return false;
  return true;
}
template <class K>
bool finite(const K* keys, unsigned n) {
  for (unsigned k = 0; k < n; ++k)
    if (!std::isfinite(keys[k].mTime) || !finite(keys[k].mValue)) return false;
  return true;
}

std::string quoted(const aiString& s) { return "'" + printable(s.C_Str()) + "'"; }

// Empty when every number keyframe reads from the scene is finite; otherwise the first that is not.
std::string non_finite_value(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    for (unsigned v = 0; v < mesh.mNumVertices; ++v)
      if (!finite(mesh.mVertices[v]))
        return "mesh " + std::to_string(m) + " " + quoted(mesh.mName) + ": vertex " + std::to_string(v) +
               " is not finite";
    for (unsigned b = 0; b < mesh.mNumBones; ++b)
      if (!finite(mesh.mBones[b]->mOffsetMatrix)) return "bone " + quoted(mesh.mBones[b]->mName) + ": offset matrix is not finite";
  }
  std::vector<const aiNode*> nodes = {scene.mRootNode};
  while (!nodes.empty()) {
    const aiNode* n = nodes.back();
    nodes.pop_back();
    if (!finite(n->mTransformation)) return "node " + quoted(n->mName) + ": transform is not finite";
    nodes.insert(nodes.end(), n->mChildren, n->mChildren + n->mNumChildren);
  }
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation& anim = *scene.mAnimations[a];
    if (!std::isfinite(anim.mDuration) || !std::isfinite(anim.mTicksPerSecond))
      return "animation " + std::to_string(a) + ": duration is not finite";
    for (unsigned c = 0; c < anim.mNumChannels; ++c) {
      const aiNodeAnim& ch = *anim.mChannels[c];
      if (!finite(ch.mPositionKeys, ch.mNumPositionKeys) || !finite(ch.mRotationKeys, ch.mNumRotationKeys) ||
          !finite(ch.mScalingKeys, ch.mNumScalingKeys))
        return "animation " + std::to_string(a) + ", channel " + quoted(ch.mNodeName) + ": a key is not finite";
    }
  }
  return "";
}

// 'S' and the scene's bytes, or 'E' and why assimp did not read it.
std::string import_to_bytes(const std::string& name, const MeshImportOptions& options,
                            std::unique_ptr<aiScene>* keep = nullptr) {
  Assimp::Importer importer;
  auto* io = new RegularFilesOnly;  // owned by the importer
  importer.SetIOHandler(io);
  importer.SetPropertyInteger(AI_CONFIG_PP_LBW_MAX_WEIGHTS, options.max_bone_weights);
  const aiScene* scene = importer.ReadFile(name, 0);
  if (!io->refused.empty()) return "E" + io->refused;
  if (!scene || !scene->mRootNode) return std::string("Ecannot read it: ") + importer.GetErrorString();
  // Checked as read: post-processing can hide a non-finite value (JoinIdenticalVertices welds a NaN vertex
  // into another one).
  if (const std::string problem = non_finite_value(*scene); !problem.empty()) return "E" + problem;
  if (options.steps) scene = importer.ApplyPostProcessing(options.steps);
  if (!io->refused.empty()) return "E" + io->refused;
  if (!scene || !scene->mRootNode) return std::string("Ecannot read it: ") + importer.GetErrorString();
  if (keep) {
    keep->reset(importer.GetOrphanedScene());
    return "S";
  }
  return "S" + scene_to_bytes(*scene);
}

bool write_all(int fd, const std::string& bytes) {
  for (size_t at = 0; at < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    at += size_t(n);
  }
  return true;
}

// The child: assimp's output and assertions go nowhere, no core file, a time limit; never returns.
[[noreturn]] void run_child(int out, const std::string& name, const MeshImportOptions& options) {
  const int null = ::open("/dev/null", O_RDWR);
  if (null >= 0) ::dup2(null, STDOUT_FILENO), ::dup2(null, STDERR_FILENO);
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  // A crash ends the child by its signal, whatever handlers the parent set (a fuzzer's, a sanitizer's).
  for (const int sig : {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE, SIGALRM}) ::signal(sig, SIG_DFL);
  if (__sanitizer_set_death_callback) __sanitizer_set_death_callback(nullptr);
  ::alarm(options.seconds);
  std::string result;
  try {
    result = import_to_bytes(name, options);
  } catch (const std::exception& e) {
    result = std::string("Ecannot read it: ") + e.what();
  }
  _exit(write_all(out, result) ? 0 : 1);
}

std::string read_all(int fd) {
  std::string bytes;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return bytes;
    bytes.append(buf, size_t(n));
  }
}

// Why the child gave no scene, from how it ended.
std::string child_failure(int status, unsigned seconds) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGALRM) return "assimp did not finish reading it in " + std::to_string(seconds) + " s";
    const char* what = sigabbrev_np(sig);
    return std::string("assimp crashed reading it (SIG") + (what ? what : std::to_string(sig).c_str()) + ")";
  }
  // An exit status: a sanitizer's report of a crash, or assimp calling exit itself.
  return "assimp crashed reading it (exit status " + std::to_string(WEXITSTATUS(status)) + ")";
}

// The child's answer, from a fork that imports the file.
std::string import_in_child(const std::string& name, const MeshImportOptions& options) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw InputError(printable(name) + ": cannot start its import: " + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw InputError(printable(name) + ": cannot start its import: " + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], name, options);
  }
  ::close(fds[1]);
  std::string bytes = read_all(fds[0]);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || bytes.empty())
    throw InputError(printable(name) + ": " + child_failure(status, options.seconds));
  return bytes;
}

}  // namespace

std::unique_ptr<aiScene> import_mesh_file(const std::filesystem::path& file, const MeshImportOptions& options) {
  const std::string name = file.string();
  if (const std::string problem = file_problem(name.c_str()); !problem.empty())
    throw InputError(printable(name) + ": " + problem);
  std::unique_ptr<aiScene> scene;
  const std::string answer = options.isolated ? import_in_child(name, options) : import_to_bytes(name, options, &scene);
  if (answer[0] == 'E') throw InputError(printable(name) + ": " + printable(std::string_view(answer).substr(1)));
  if (options.isolated) {
    try {
      scene = scene_from_bytes(std::string_view(answer).substr(1));
    } catch (const MeshWireError& e) {
      throw InputError(printable(name) + ": the import's answer did not decode (" + e.what() + ")");
    }
  }
  if (const std::string problem = non_finite_value(*scene); !problem.empty())
    throw InputError(printable(name) + ": " + problem);
  return scene;
}

}  // namespace kf
