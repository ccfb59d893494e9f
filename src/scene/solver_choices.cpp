#include "scene/solver_choices.h"

#include <stdexcept>

namespace kf {

namespace {
// The index of `name` in `names` as the enum E; throws naming what `what` expects.
template <class E>
E by_name(const std::vector<std::string>& names, const std::string& name, const char* what) {
  for (size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return E(k);
  std::string expected;
  for (const std::string& n : names) expected += (expected.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown " + std::string(what) + " \"" + name + "\" (expected one of " + expected + ")");
}
}  // namespace

const std::vector<std::string>& adjoint_names() {
  static const std::vector<std::string> names = {"exact", "swap"};
  return names;
}

const char* adjoint_name(AdjointKind kind) { return adjoint_names()[size_t(kind)].c_str(); }

AdjointKind adjoint_kind(const std::string& name) { return by_name<AdjointKind>(adjoint_names(), name, "adjoint"); }

const std::vector<std::string>& cg_preconditioner_names() {
  static const std::vector<std::string> names = {"auto", "incomplete_cholesky", "multigrid", "block_jacobi"};
  return names;
}

const char* cg_preconditioner_name(CgPreconditioner p) { return cg_preconditioner_names()[size_t(p)].c_str(); }

CgPreconditioner cg_preconditioner(const std::string& name) {
  return by_name<CgPreconditioner>(cg_preconditioner_names(), name, "cg_preconditioner");
}

}  // namespace kf
