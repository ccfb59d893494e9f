#pragma once
// The solver choices a scene file names (optimizer.adjoint, cloth.cg_preconditioner), read once here into
// enums: later layers decide by the enum and print its name from here, never compare the text.
#include <string>
#include <vector>

namespace kf {

// optimizer.adjoint (and --adjoint): the cloth adjoint, "exact" (the transpose of the step's Jacobian) or
// "swap" (the paper's integrator swap).
enum class AdjointKind { kExact, kSwap };
// cloth.cg_preconditioner: "auto" (the cloth system picks by the sheet's size), "incomplete_cholesky",
// "multigrid" or "block_jacobi".
enum class CgPreconditioner { kAuto, kIncompleteCholesky, kMultigrid, kBlockJacobi };

const char* adjoint_name(AdjointKind kind);
const std::vector<std::string>& adjoint_names();  // every kind's name, in the enum's order
// The kind named `name`; throws std::invalid_argument naming the expected names on any other.
AdjointKind adjoint_kind(const std::string& name);

const char* cg_preconditioner_name(CgPreconditioner p);
const std::vector<std::string>& cg_preconditioner_names();
CgPreconditioner cg_preconditioner(const std::string& name);  // throws std::invalid_argument on others

}  // namespace kf
