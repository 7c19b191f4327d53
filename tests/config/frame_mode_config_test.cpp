// frame_mode per camera and the camera timing it needs: parsed, and every inconsistency named
// by key and line before a camera is touched.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "config_test_support.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config {
namespace {
using test_support::dump;
using test_support::line_containing;

std::string aravis_camera(const std::string& id, const std::string& mode, const std::string& extra = "") {
  return "[[cameras]]\nid = \"" + id + "\"\nbackend = \"aravis\"\ndevice_id = \"127.0.0.1\"\n" +
         (mode.empty() ? "" : "frame_mode = \"" + mode + "\"\n") + extra;
}

const std::string kTrigger = "[trigger]\nbackend = \"simulated\"\nrate_hz = 5\ndt_us = 60000\n";

const ConfigIssue* issue_for(const std::vector<ConfigIssue>& issues, const std::string& key) {
  const auto it = std::find_if(issues.begin(), issues.end(), [&](const ConfigIssue& i) { return i.key == key; });
  return it == issues.end() ? nullptr : &*it;
}

TEST(FrameMode, DefaultsToHardwareAndReadsEveryMode) {
  const RigConfig rig = parse_rig_config(aravis_camera("a", "") + aravis_camera("b", "free_run") + kTrigger);
  EXPECT_EQ(rig.cameras[0].frame_mode, FrameMode::hardware);
  EXPECT_EQ(rig.cameras[1].frame_mode, FrameMode::free_run);
  const RigConfig two = parse_rig_config(aravis_camera("a", "two_triggers") + kTrigger +
                                         "[trigger.camera]\nreadout_us = 40000\nframe_time_tolerance_us = 25000\n");
  EXPECT_EQ(two.cameras[0].frame_mode, FrameMode::two_triggers);
  EXPECT_DOUBLE_EQ(two.trigger.camera.readout_us, 40000.0);
  ASSERT_TRUE(two.trigger.camera.frame_time_tolerance_us);
  EXPECT_DOUBLE_EQ(*two.trigger.camera.frame_time_tolerance_us, 25000.0);
  EXPECT_EQ(to_string(FrameMode::two_triggers), "two_triggers");
}

TEST(FrameMode, UnknownModeListsTheModes) {
  const std::string doc = aravis_camera("a", "double") + kTrigger;
  const auto issues = check_rig_config(doc, "rig.toml");
  const ConfigIssue* issue = issue_for(issues, "cameras[0].frame_mode");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_EQ(issue->line, line_containing(doc, "frame_mode"));
  EXPECT_NE(issue->message.find("hardware, two_triggers, free_run"), std::string::npos) << issue->message;
}

TEST(FrameMode, TwoTriggersWithoutAReadoutTimeSaysWhatToAdd) {
  const std::string doc = aravis_camera("a", "two_triggers") + kTrigger;
  const auto issues = check_rig_config(doc, "rig.toml");
  const ConfigIssue* issue = issue_for(issues, "cameras[0].frame_mode");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_NE(issue->message.find("readout_us"), std::string::npos) << issue->message;
  EXPECT_NE(issue->message.find("[trigger.camera]"), std::string::npos) << issue->message;
}

TEST(FrameMode, TriggeredCamerasShareOneModeButFreeRunningOnesMayDiffer) {
  const std::string doc = aravis_camera("a", "hardware") + aravis_camera("b", "free_run") +
                          aravis_camera("c", "two_triggers") + kTrigger + "[trigger.camera]\nreadout_us = 40000\n";
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_EQ(issues[0].key, "cameras[2].frame_mode");
  EXPECT_NE(issues[0].message.find("cameras[0]"), std::string::npos) << issues[0].message;
  EXPECT_NE(issues[0].message.find("\"hardware\""), std::string::npos) << issues[0].message;
}

TEST(FrameMode, FreeRunIsForRealCamerasOnly) {
  const std::string doc = "[[cameras]]\nid = \"s\"\nbackend = \"simulated\"\nframe_mode = \"free_run\"\n"
                          "[cameras.roi]\nwidth = 8\nheight = 8\n";
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_NE(issue_for(issues, "cameras[0].frame_mode"), nullptr) << dump(issues);
}

TEST(FrameMode, AVerbatimExposureFeatureMustAgreeWithThePlan) {
  // [trigger.camera] exposure_a_us is what the plan writes to every camera.
  const std::string timing = "[trigger.camera]\nexposure_a_us = 500\n";
  EXPECT_TRUE(check_rig_config(aravis_camera("a", "", "[cameras.features]\nExposureTime = 500\n") + kTrigger + timing)
                  .empty());
  const std::string doc = aravis_camera("a", "", "[cameras.features]\nExposureTimeAbs = 200.0\n") + kTrigger + timing;
  const auto issues = check_rig_config(doc, "rig.toml");
  const ConfigIssue* issue = issue_for(issues, "cameras[0].features.ExposureTimeAbs");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_EQ(issue->line, line_containing(doc, "ExposureTimeAbs"));
  EXPECT_NE(issue->message.find("contradicts the timing plan"), std::string::npos) << issue->message;
  EXPECT_NE(issue->message.find("exposure_a_us"), std::string::npos) << issue->message;
  EXPECT_NE(issue->message.find("500"), std::string::npos) << issue->message;
  const auto text = check_rig_config(aravis_camera("a", "", "[cameras.features]\nExposureTime = \"long\"\n") + kTrigger);
  ASSERT_NE(issue_for(text, "cameras[0].features.ExposureTime"), nullptr) << dump(text);
}

TEST(FrameMode, ReadoutAndToleranceMustBePositive) {
  const auto issues = check_rig_config(aravis_camera("a", "") + kTrigger +
                                       "[trigger.camera]\nreadout_us = 0\nframe_time_tolerance_us = -1\n");
  EXPECT_NE(issue_for(issues, "trigger.camera.readout_us"), nullptr) << dump(issues);
  EXPECT_NE(issue_for(issues, "trigger.camera.frame_time_tolerance_us"), nullptr) << dump(issues);
}

}  // namespace
}  // namespace tomorig::config
