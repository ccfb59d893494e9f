// The solver choices a scene file names (optimizer.adjoint, cloth.cg_preconditioner) are read once into
// enums (scene/solver_choices.h): each name gives its enum and back, the scene's keys set them, and any other
// name is refused, naming the key or the names expected.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace kf {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(SolverChoices, EachNameReadsIntoItsEnumAndBack) {
  ASSERT_EQ(adjoint_names().size(), 2u);
  for (const AdjointKind k : {AdjointKind::kExact, AdjointKind::kSwap}) EXPECT_EQ(adjoint_kind(adjoint_name(k)), k);
  EXPECT_STREQ(adjoint_name(AdjointKind::kSwap), "swap");
  ASSERT_EQ(cg_preconditioner_names().size(), 4u);
  for (const CgPreconditioner p : {CgPreconditioner::kAuto, CgPreconditioner::kIncompleteCholesky,
                                   CgPreconditioner::kMultigrid, CgPreconditioner::kBlockJacobi})
    EXPECT_EQ(cg_preconditioner(cg_preconditioner_name(p)), p);
  EXPECT_STREQ(cg_preconditioner_name(CgPreconditioner::kMultigrid), "multigrid");
  try {
    adjoint_kind("Exact");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown adjoint \"Exact\" (expected one of exact, swap)");
  }
  EXPECT_THROW(cg_preconditioner("ilu"), std::invalid_argument);
}

TEST(SolverChoices, TheSceneKeysSetThemAndOtherNamesAreRefused) {
  const std::string cloth = R"("cloth": {"nx": 3, "ny": 3)";
  const Scene defaults = parse_scene("{" + cloth + "}}", "s.json");
  EXPECT_EQ(defaults.optimizer.adjoint, AdjointKind::kExact);
  EXPECT_EQ(defaults.cloth->cg_preconditioner, CgPreconditioner::kAuto);
  const Scene set = parse_scene(
      "{" + cloth + R"(, "cg_preconditioner": "multigrid"}, "optimizer": {"adjoint": "swap"}})", "s.json");
  EXPECT_EQ(set.optimizer.adjoint, AdjointKind::kSwap);
  EXPECT_EQ(set.cloth->cg_preconditioner, CgPreconditioner::kMultigrid);
  EXPECT_NE(error_of("{" + cloth + R"(}, "optimizer": {"adjoint": "transpose"}})").find("/optimizer/adjoint: expected one of"),
            std::string::npos);
  EXPECT_NE(error_of("{" + cloth + R"(, "cg_preconditioner": "Multigrid"}})").find("/cloth/cg_preconditioner: expected one of"),
            std::string::npos);
}

}  // namespace
}  // namespace kf
