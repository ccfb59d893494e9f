#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/params.h"
#include "scene/render_spec.h"

namespace kf {

TEST(RenderSpec, DefaultsWithoutCamera) {
  Block b(Json::object(), "s.json", "/render");
  const RenderSpec s = parse_render_spec(b);
  EXPECT_FALSE(s.has_camera);
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 480);
  EXPECT_NEAR(s.light_direction.norm(), 1.0, 1e-12);
}

TEST(RenderSpec, ReadsCameraAndColours) {
  Block b(Json::parse(R"({"width": 320, "height": 200, "camera": {"eye": [0, 4, 8], "target": [0, 0, 0], "fov": 30},
                          "cloth_front": [0.1, 0.2, 0.3], "light_direction": [0, 2, 0]})"),
          "s.json", "/render");
  const RenderSpec s = parse_render_spec(b);
  EXPECT_TRUE(s.has_camera);
  EXPECT_EQ(s.camera.eye, Vec3(0, 4, 8));
  EXPECT_EQ(s.camera.fov, 30.0);
  EXPECT_EQ(s.cloth_front, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(s.light_direction, Vec3(0, 1, 0));
}

TEST(RenderSpec, RejectsUnknownKeysAndBadValues) {
  auto message = [](const char* text) {
    Block b(Json::parse(text), "s.json", "/render");
    try {
      parse_render_spec(b);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(R"({"widht": 10})").find("/render/widht"), std::string::npos);
  EXPECT_NE(message(R"({"camera": {"eye": [0,1,2], "target": [0,0,0], "lens": 3}})").find("/render/camera/lens"),
            std::string::npos);
  EXPECT_NE(message(R"({"camera": {"eye": [0,1,0], "target": [0,0,0]}})").find("/render/camera/up"),
            std::string::npos);
  EXPECT_NE(message(R"({"agent_color": [2, 0, 0]})").find("/render/agent_color"), std::string::npos);
  EXPECT_NE(message(R"({"width": 0})").find("/render/width"), std::string::npos);
}

}  // namespace kf
