#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/params.h"

namespace kf {

TEST(Block, ReadsDefaultsAndRejectsUnknownKeys) {
  Block b(Json::parse(R"({"a": 2, "typo": 1})"), "s.json");
  EXPECT_EQ(b.integer("a", 0, 0, 10), 2);
  EXPECT_EQ(b.number("b", 1.5, 0, 10), 1.5);
  try {
    b.finish();
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "s.json: /typo: unknown key (check its spelling; see README 'Scene files')");
  }
}

}  // namespace kf
