// The one camera-id rule (issue 14, defects 5 and 7): UTF-8, no NUL or other control
// characters, no '/', not "." or "..", and a length limit; messages never echo raw bytes.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"

namespace tomorig {
namespace {

using namespace std::string_literals;

TEST(CameraId, OrdinaryIdsAreValid) {
  for (const std::string id : {"cam0"s, "A"s, "cam-1_left.top"s, "kamera \xc3\xa4"s, "\xe6\x97\xa5\xe6\x9c\xac"s,
                               "...x"s, std::string(kMaxCameraIdBytes, 'c')})
    EXPECT_EQ(camera_id_problem(id), std::nullopt) << id;
}

TEST(CameraId, EveryForbiddenKindIsRefusedWithItsReason) {
  struct Case {
    std::string id;
    std::string reason;
  };
  for (const Case& c : {Case{"", "empty"}, Case{"a/b", "'/'"}, Case{"/", "'/'"}, Case{".", "'.' or '..'"},
                        Case{"..", "'.' or '..'"}, Case{"a\0b"s, "NUL"}, Case{"cam\x1b[31m", "U+001B"},
                        Case{"tab\there", "U+0009"}, Case{"del\x7f", "U+007F"}, Case{"c1\xc2\x85", "U+0085"},
                        Case{"\xff", "not valid UTF-8"}, Case{"a\xc3", "not valid UTF-8"},
                        Case{"\xc0\xaf", "not valid UTF-8"},        // overlong '/'
                        Case{"\xed\xa0\x80", "not valid UTF-8"},    // a UTF-16 surrogate
                        Case{"\xf4\x90\x80\x80", "not valid UTF-8"},  // past U+10FFFF
                        Case{std::string(kMaxCameraIdBytes + 1, 'c'), "bytes long"}}) {
    const auto problem = camera_id_problem(c.id);
    ASSERT_TRUE(problem.has_value()) << printable(c.id);
    EXPECT_NE(problem->find(c.reason), std::string::npos) << *problem;
  }
}

TEST(CameraId, MessagesShowBytesEscapedAndNameTheContext) {
  EXPECT_EQ(printable("cam\x1b[2J\\\xff"), "cam\\x1b[2J\\\\\\xff");
  EXPECT_EQ(printable(std::string(100, 'x')), std::string(64, 'x') + "...");
  try {
    require_valid_camera_id("evil\x1b]0;title\x07", "rig.toml cameras[2].id");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    const std::string message = e.what();
    EXPECT_NE(message.find("rig.toml cameras[2].id"), std::string::npos) << message;
    EXPECT_NE(message.find("evil\\x1b]0;title\\x07"), std::string::npos) << message;
    EXPECT_EQ(message.find('\x1b'), std::string::npos) << "raw escape byte in the message";
  }
}

}  // namespace
}  // namespace tomorig
