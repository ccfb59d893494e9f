// The default controls.kind, as the user meets it: `keyframe schema` names it, and it is the kind every
// shipped example writes out (tests/results/shots/README.md, "One default controls.kind").
#include <gtest/gtest.h>

#include <algorithm>

#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class ControlsDefault : public TempDirTest {};

TEST_F(ControlsDefault, SchemaNamesPerFrame) {
  const auto r = run_keyframe("schema", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json schema = Json::parse(r.output);
  const Json& kind = schema.at("properties").at("controls").at("properties").at("kind");
  EXPECT_EQ(kind.at("default"), "per_frame");
  // per_step stays a kind a scene may ask for.
  const Json& kinds = kind.at("enum");
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "per_step"), kinds.end());
}

}  // namespace
}  // namespace kf
