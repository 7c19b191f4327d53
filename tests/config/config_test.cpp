// The rig config parser: the embedded default, and every class of problem it reports, each
// named by key path and line.
#include "temp_dir.h"
#include "config_test_support.h"
#include "tomorig/config/rig_config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "tomorig/core/error.h"

namespace tomorig::config {
namespace {
using test_support::dump;
using test_support::line_containing;

// ---- helpers ------------------------------------------------------------------------------

// A minimal valid rig: one simulated camera. `camera_extra` goes into the [[cameras]] table,
// `roi` replaces the ROI body, `tail` follows the camera (further tables).
std::string rig_with(const std::string& camera_extra = "", const std::string& tail = "",
                     const std::string& roi = "width = 64\nheight = 48\n") {
  return "[[cameras]]\n"
         "id = \"a\"\n"
         "backend = \"simulated\"\n" +
         camera_extra + "\n[cameras.roi]\n" + roi + "\n" + tail;
}


const ConfigIssue* find_issue(const std::vector<ConfigIssue>& issues, const std::string& key) {
  auto it = std::find_if(issues.begin(), issues.end(), [&](const ConfigIssue& i) { return i.key == key; });
  return it == issues.end() ? nullptr : &*it;
}


// Expects an issue for `key` on the line holding `at` (a fragment of the fixture) whose
// message contains `text`.
void expect_issue(const std::string& doc, const std::string& key, const std::string& at, const std::string& text) {
  const auto issues = check_rig_config(doc, "rig.toml");
  const ConfigIssue* issue = find_issue(issues, key);
  ASSERT_NE(issue, nullptr) << "no issue for " << key << "; got:\n" << dump(issues) << "in:\n" << doc;
  // An empty `at`: the issue has no line (a key missing from the document root).
  EXPECT_EQ(issue->line, at.empty() ? 0 : line_containing(doc, at)) << issue->to_string();
  EXPECT_NE(issue->message.find(text), std::string::npos) << issue->to_string() << "\nwanted: " << text;
  EXPECT_EQ(issue->origin, "rig.toml");
}

using testing::TempDir;
std::string read_file(const std::filesystem::path& path) { return testing::read_text_file(path); }

// ---- the default rig ----------------------------------------------------------------------

TEST(DefaultRig, IsValid) {
  EXPECT_TRUE(check_rig_config(default_rig_toml(), "default-rig.toml").empty())
      << dump(check_rig_config(default_rig_toml(), "default-rig.toml"));
  EXPECT_NO_THROW(default_rig_config());
}

TEST(DefaultRig, IsTheFileInTheRepository) {
  // One source of truth: the embedded text is config/default-rig.toml byte for byte.
  EXPECT_EQ(default_rig_toml(), read_file(std::filesystem::path(TOMORIG_SOURCE_DIR) / "config/default-rig.toml"));
  EXPECT_EQ(default_rig_config().source_text, default_rig_toml());
}

TEST(DefaultRig, HasTheTpivThesisCameras) {
  const RigConfig rig = default_rig_config();
  ASSERT_EQ(rig.cameras.size(), 4u);
  const double yaws[] = {-42.0, -14.0, 14.0, 42.0};
  for (std::size_t i = 0; i < 4; ++i) {
    const CameraConfig& cam = rig.cameras[i];
    SCOPED_TRACE(cam.id);
    EXPECT_EQ(cam.id, "cam" + std::to_string(i));
    EXPECT_EQ(cam.backend, CameraBackend::simulated);
    EXPECT_DOUBLE_EQ(cam.yaw_deg, yaws[i]);
    EXPECT_EQ(cam.roi.offset_x, 0);
    EXPECT_EQ(cam.roi.offset_y, 0);
    EXPECT_EQ(cam.roi.width, 512);
    EXPECT_EQ(cam.roi.height, 512);
    EXPECT_EQ(cam.pixel_format, PixelFormat::Mono16);
    EXPECT_DOUBLE_EQ(cam.pixel_pitch_um, 7.4);
    EXPECT_DOUBLE_EQ(cam.focal_length_mm, 100.0);
    EXPECT_DOUBLE_EQ(cam.distance_mm, 263.16);
    EXPECT_TRUE(cam.features.empty());
    // Benchmark geometry: magnification 0.38 at the origin, so 1 px is about 1 voxel.
    const double magnification = cam.focal_length_mm / cam.distance_mm;
    EXPECT_NEAR(magnification, 0.38, 1e-4);
    EXPECT_NEAR(cam.pixel_pitch_um * 1e-3 / magnification, rig.grid.voxel_size_mm, 1e-4);
    EXPECT_NEAR(cam.focal_length_mm / (cam.pixel_pitch_um * 1e-3), 13513.5, 0.1);
  }
}

TEST(DefaultRig, HasTheTpivThesisGridTriggerAndScene) {
  const RigConfig rig = default_rig_config();
  EXPECT_EQ(rig.trigger.backend, TriggerBackend::simulated);
  EXPECT_DOUBLE_EQ(rig.trigger.rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(rig.trigger.dt_us, 100.0);
  EXPECT_DOUBLE_EQ(rig.trigger.pulse_width_us, 0.01);
  EXPECT_EQ(rig.grid.nx, 512);
  EXPECT_EQ(rig.grid.ny, 512);
  EXPECT_EQ(rig.grid.nz, 160);
  EXPECT_DOUBLE_EQ(rig.grid.voxel_size_mm, 0.0195);
  for (double o : rig.grid.origin_mm) EXPECT_EQ(o, 0.0);
  EXPECT_EQ(rig.processing.algorithm, "");  // absent: the reconstruction library's default
  EXPECT_EQ(rig.processing.iterations, 0);
  EXPECT_FALSE(rig.calibration_file.has_value());
  ASSERT_TRUE(rig.simulation.has_value());
  const SimulationConfig& sim = *rig.simulation;
  EXPECT_EQ(sim.case_name, "tpiv-thesis");
  EXPECT_DOUBLE_EQ(sim.ppp, 0.05);
  EXPECT_EQ(sim.seed, 1u);
  EXPECT_EQ(sim.sets, 2);
  EXPECT_EQ(sim.bit_depth, 16);
  EXPECT_FALSE(sim.noise);
  EXPECT_DOUBLE_EQ(sim.peak_counts, 1000.0);
  EXPECT_EQ(sim.light_sheet, LightSheetProfile::uniform);
}

TEST(DefaultRig, KnowsItsSimulationCase) {
  const auto& names = simulation_case_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "tpiv-thesis"), names.end());
}

// ---- valid input --------------------------------------------------------------------------

TEST(ParseRig, MinimalRigTakesDefaults) {
  const RigConfig rig = parse_rig_config(rig_with());
  ASSERT_EQ(rig.cameras.size(), 1u);
  EXPECT_EQ(rig.name, "tomorig rig");
  EXPECT_EQ(rig.cameras[0].device_id, "a");  // simulated: the view is named after the camera
  EXPECT_EQ(rig.cameras[0].pixel_format, PixelFormat::Mono16);
  EXPECT_EQ(rig.trigger.backend, TriggerBackend::simulated);
  EXPECT_EQ(rig.grid.nz, 160);
  EXPECT_EQ(rig.processing.algorithm, "");  // absent: the reconstruction library's default
  EXPECT_FALSE(rig.simulation.has_value());
  EXPECT_FALSE(rig.calibration_file.has_value());
}

TEST(ParseRig, NumbersAcceptIntegers) {
  const RigConfig rig = parse_rig_config(
      rig_with("pixel_pitch_um = 5\nfocal_length_mm = 50\ndistance_mm = 300",
               "[trigger]\nbackend = \"simulated\"\nrate_hz = 15\ndt_us = 20\npulse_width_us = 1\n"
               "[grid]\nvoxel_size_mm = 1\norigin_mm = [1, 2.5, -3]\n"
               "[simulation]\nppp = 1\npeak_counts = 4000\nbit_depth = 12\n"));
  EXPECT_DOUBLE_EQ(rig.cameras[0].pixel_pitch_um, 5.0);
  EXPECT_DOUBLE_EQ(rig.trigger.rate_hz, 15.0);
  EXPECT_DOUBLE_EQ(rig.grid.voxel_size_mm, 1.0);
  EXPECT_DOUBLE_EQ(rig.grid.origin_mm[0], 1.0);
  EXPECT_DOUBLE_EQ(rig.grid.origin_mm[1], 2.5);
  EXPECT_DOUBLE_EQ(rig.grid.origin_mm[2], -3.0);
  EXPECT_DOUBLE_EQ(rig.simulation->ppp, 1.0);
}

TEST(ParseRig, ReadsAravisCamerasGpioTriggerAndFeatures) {
  const std::string doc = R"(name = "tunnel"
[[cameras]]
id = "left"
backend = "aravis"
device_id = "Basler-1234"
pixel_format = "Mono12"
[cameras.features]
ExposureTime = 20.0
Gain = 3
ReverseX = true
GainAuto = "Off"
"Dotted.Name" = 1.5

[trigger]
backend = "gpio"
[[trigger.channels]]
name = "laser1"
role = "light"
chip = "gpiochip0"
line = 17
[[trigger.channels]]
name = "cams"
role = "camera"
chip = "gpiochip0"
line = 18

[calibration]
file = "/data/calib.h5"

[processing]
algorithm = "smart"
iterations = 20
)";
  const RigConfig rig = parse_rig_config(doc);
  EXPECT_EQ(rig.name, "tunnel");
  const CameraConfig& cam = rig.cameras.at(0);
  EXPECT_EQ(cam.backend, CameraBackend::aravis);
  EXPECT_EQ(cam.device_id, "Basler-1234");
  EXPECT_EQ(cam.pixel_format, PixelFormat::Mono12);
  EXPECT_EQ(cam.roi.width, 0);  // no ROI: the full sensor
  EXPECT_EQ(cam.features.at("ExposureTime"), "20");  // what [trigger.camera] exposure_a_us says (default 20)
  EXPECT_EQ(cam.features.at("Gain"), "3");
  EXPECT_EQ(cam.features.at("ReverseX"), "true");
  EXPECT_EQ(cam.features.at("GainAuto"), "Off");
  EXPECT_EQ(cam.features.at("Dotted.Name"), "1.5");
  EXPECT_EQ(rig.trigger.backend, TriggerBackend::gpio);
  ASSERT_EQ(rig.trigger.channels.size(), 2u);
  EXPECT_EQ(rig.trigger.channels[0].name, "laser1");
  EXPECT_EQ(rig.trigger.channels[0].role, ChannelRole::light);
  EXPECT_EQ(rig.trigger.channels[0].chip, "gpiochip0");
  EXPECT_EQ(rig.trigger.channels[1].line, 18);
  ASSERT_TRUE(rig.calibration_file.has_value());
  EXPECT_EQ(*rig.calibration_file, std::filesystem::path("/data/calib.h5"));
  EXPECT_EQ(rig.processing.algorithm, "smart");
  EXPECT_EQ(rig.processing.iterations, 20);
}

TEST(ParseRig, InlineTablesWork) {
  const RigConfig rig = parse_rig_config(
      "cameras = [{ id = \"x\", backend = \"simulated\", roi = { width = 8, height = 8 } }]\n");
  ASSERT_EQ(rig.cameras.size(), 1u);
  EXPECT_EQ(rig.cameras[0].roi.width, 8);
}

// ---- issue classes: each names the key path and the line ---------------------------------

TEST(RigIssues, UnsupportedPixelFormatMessageIsExact) {
  const std::string doc = R"([[cameras]]
id = "a"
backend = "aravis"
device_id = "A"
[[cameras]]
id = "b"
backend = "aravis"
device_id = "B"
[[cameras]]
id = "c"
backend = "aravis"
pixel_format = "Mono14"
device_id = "C"
)";
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_EQ(issues[0].to_string(),
            "rig.toml:12: cameras[2].pixel_format: \"Mono14\" is not supported (Mono8, Mono12, Mono16)");
}

TEST(RigIssues, SyntaxErrorHasLineAndColumn) {
  const std::string doc = rig_with("", "[grid]\nnx = 12\nny = = 3\n");
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_EQ(issues[0].line, line_containing(doc, "ny = = 3"));
  EXPECT_GT(issues[0].column, 0);
  EXPECT_EQ(issues[0].key, "");
  EXPECT_NE(issues[0].message.find("invalid TOML"), std::string::npos);
  EXPECT_EQ(issues[0].to_string().rfind("rig.toml:" + std::to_string(issues[0].line) + ":" +
                                            std::to_string(issues[0].column) + ": invalid TOML",
                                        0),
            0u)
      << issues[0].to_string();
}

TEST(RigIssues, RedefinedKeyIsASyntaxError) {
  const std::string doc = rig_with("id = \"b\"");
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_EQ(issues[0].line, 4);
}

TEST(RigIssues, TypeErrors) {
  expect_issue(rig_with("", "[trigger]\nbackend = \"simulated\"\nrate_hz = \"fast\"\n"), "trigger.rate_hz",
               "rate_hz", "expected a number, got string \"fast\"");
  expect_issue(rig_with("", "[grid]\nnx = 2.5\n"), "grid.nx", "nx = 2.5", "expected an integer, got float 2.5");
  expect_issue(rig_with("", "[grid]\nny = 512.0\n"), "grid.ny", "ny", "expected an integer, got float 512.0");
  expect_issue(rig_with("", "[simulation]\nnoise = 1\n"), "simulation.noise", "noise = 1",
               "expected a boolean (true or false), got integer 1");
  expect_issue("name = 3\n" + rig_with(), "name", "name = 3", "expected a string, got integer 3");
  expect_issue(rig_with("", "", "width = \"wide\"\nheight = 4\n"), "cameras[0].roi.width", "wide",
               "expected an integer, got string \"wide\"");
  expect_issue(rig_with("", "", "width = 4\nheight = [4]\n"), "cameras[0].roi.height", "height = [4]",
               "expected an integer, got an array");
  expect_issue("grid = 5\n" + rig_with(), "grid", "grid = 5", "expected a table [grid], got integer 5");
  expect_issue(rig_with("", "[grid]\norigin_mm = [0, \"a\", 0]\n"), "grid.origin_mm[1]", "origin_mm",
               "expected a finite number, got string \"a\"");
  expect_issue(rig_with("", "[grid]\norigin_mm = [0, 0]\n"), "grid.origin_mm", "origin_mm",
               "expected an array of 3 numbers, got 2");
  expect_issue(rig_with("", "[grid]\norigin_mm = 0\n"), "grid.origin_mm", "origin_mm",
               "expected an array of 3 numbers, got integer 0");
  expect_issue(rig_with("", "[grid]\nnx = 9999999999\n"), "grid.nx", "nx", "out of range");
  expect_issue(rig_with("", "[trigger]\nbackend = \"gpio\"\nchannels = 3\n"), "trigger.channels", "channels = 3",
               "expected an array of tables ([[trigger.channels]])");
  expect_issue(rig_with("", "[trigger]\nbackend = \"simulated\"\nrate_hz = inf\n"), "trigger.rate_hz", "rate_hz",
               "must be a finite number");
  expect_issue(rig_with("[cameras.features]\nLUT = [1, 2]"), "cameras[0].features.LUT", "LUT",
               "expected a string, number or boolean, got an array");
  expect_issue(rig_with("[cameras.features]\n\"A.B\" = {x = 1}"), "cameras[0].features.\"A.B\"", "A.B",
               "expected a string, number or boolean, got a table");
  expect_issue("[cameras]\nid = \"a\"\n", "cameras", "[cameras]", "expected an array of tables ([[cameras]]), got a table");
  expect_issue("cameras = [1]\n", "cameras[0]", "cameras", "expected a table, got integer 1");
  expect_issue(rig_with("", "[simulation]\nseed = -3\n"), "simulation.seed", "seed", "-3 must be >= 0");
}

TEST(RigIssues, UnknownKeysAtEveryLevel) {
  expect_issue("nmae = \"x\"\n" + rig_with(), "nmae", "nmae", "did you mean \"name\"?");
  expect_issue(rig_with("", "[grdi]\nnx = 1\n"), "grdi", "[grdi]", "did you mean \"grid\"?");
  expect_issue(rig_with("pixel_fromat = \"Mono8\""), "cameras[0].pixel_fromat", "pixel_fromat",
               "did you mean \"pixel_format\"?");
  expect_issue(rig_with("", "", "widht = 4\nwidth = 4\nheight = 4\n"), "cameras[0].roi.widht", "widht",
               "did you mean \"width\"?");
  expect_issue(rig_with("", "[trigger]\nbackend = \"simulated\"\ndt = 3\n"), "trigger.dt", "dt = 3",
               "did you mean \"dt_us\"?");
  expect_issue(rig_with("", "[trigger]\nbackend = \"simulated\"\n[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\n"
                            "pin = 4\n"),
               "trigger.channels[0].pin", "pin", "unknown key");
  expect_issue(rig_with("", "[grid]\nvoxel_size = 0.1\n"), "grid.voxel_size", "voxel_size", "did you mean \"voxel_size_mm\"?");
  expect_issue(rig_with("", "[processing]\nalgoritm = \"mart\"\n"), "processing.algoritm", "algoritm",
               "did you mean \"algorithm\"?");
  expect_issue(rig_with("", "[simulation]\nnosie = true\n"), "simulation.nosie", "nosie", "did you mean \"noise\"?");
  expect_issue(rig_with("", "[calibration]\nfile = \"c.h5\"\npath = \"x\"\n"), "calibration.path", "path =",
               "unknown key (allowed: file)");
}

TEST(RigIssues, UnknownKeyListsAllowedKeysAndOnlySuggestsCloseOnes) {
  const std::string doc = rig_with("", "[processing]\nzzzzzz = 1\n");
  const auto issues = check_rig_config(doc);
  const ConfigIssue* issue = find_issue(issues, "processing.zzzzzz");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_EQ(issue->message, "unknown key (allowed: algorithm, iterations)");
}

TEST(RigIssues, MissingRequiredKeys) {
  expect_issue("name = \"empty\"\n", "cameras", "", "required key is missing (expected at least one [[cameras]] entry)");
  expect_issue("cameras = []\n", "cameras", "cameras = []", "expected at least one [[cameras]] entry, got none");
  const std::string no_id = rig_with("", "[[cameras]]\nbackend = \"aravis\"\ndevice_id = \"x\"\n");
  // A missing key is reported at its table's header: the second [[cameras]].
  const auto issues = check_rig_config(no_id, "rig.toml");
  const ConfigIssue* issue = find_issue(issues, "cameras[1].id");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_EQ(issue->line, 9) << no_id;
  EXPECT_EQ(issue->message, "required key is missing (expected a string)");

  expect_issue("[[cameras]]\nid = \"a\"\n", "cameras[0].backend", "[[cameras]]", "required key is missing");
  expect_issue("[[cameras]]\nid = \"a\"\nbackend = \"aravis\"\n", "cameras[0].device_id", "[[cameras]]",
               "required key is missing");
  expect_issue("[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n", "cameras[0].roi", "[[cameras]]",
               "required for simulated cameras");
  expect_issue(rig_with("", "", "width = 4\n"), "cameras[0].roi.height", "[cameras.roi]", "required key is missing");
  expect_issue(rig_with("", "[trigger]\nrate_hz = 5\n"), "trigger.backend", "[trigger]", "required key is missing");
  expect_issue(rig_with("", "[trigger]\nbackend = \"gpio\"\n"), "trigger.channels", "[trigger]",
               "expected at least one [[trigger.channels]] entry");
  const std::string gpio = rig_with("", "[trigger]\nbackend = \"gpio\"\n[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\n");
  expect_issue(gpio, "trigger.channels[0].chip", "[[trigger.channels]]", "required key is missing");
  expect_issue(gpio, "trigger.channels[0].line", "[[trigger.channels]]", "required key is missing");
  expect_issue(rig_with("", "[trigger]\nbackend = \"simulated\"\n[[trigger.channels]]\nname = \"l\"\n"),
               "trigger.channels[0].role", "[[trigger.channels]]", "required key is missing");
  expect_issue(rig_with("", "[calibration]\n"), "calibration.file", "[calibration]", "required key is missing");
}

TEST(RigIssues, DuplicateCameraIds) {
  const std::string doc = rig_with("", "[[cameras]]\nid = \"a\"\nbackend = \"aravis\"\ndevice_id = \"x\"\n");
  const auto issues = check_rig_config(doc, "rig.toml");
  const ConfigIssue* issue = find_issue(issues, "cameras[1].id");
  ASSERT_NE(issue, nullptr) << dump(issues);
  EXPECT_EQ(issue->line, 10);
  EXPECT_EQ(issue->message, "\"a\" is already used by cameras[0] (line 2); camera ids must be unique");
}

TEST(RigIssues, DuplicateChannelNamesAndLines) {
  const std::string doc = rig_with(
      "", "[trigger]\nbackend = \"gpio\"\n"
          "[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\nchip = \"gpiochip0\"\nline = 4\n"
          "[[trigger.channels]]\nname = \"l\" # second\nrole = \"camera\"\nchip = \"gpiochip0\"\nline = 4 # again\n");
  expect_issue(doc, "trigger.channels[1].name", "# second", "\"l\" is already used by trigger.channels[0]");
  expect_issue(doc, "trigger.channels[1].line", "# again", "gpiochip0 line 4 is already used by trigger.channels[0]");
}

struct RangeCase {
  const char* name;
  std::string doc;
  const char* key;
  const char* at;       // a fragment of the line the issue must point at
  const char* message;  // the message must contain this
};

class RangeIssues : public ::testing::TestWithParam<RangeCase> {};

TEST_P(RangeIssues, NameKeyLineAndWhatIsAllowed) {
  const RangeCase& c = GetParam();
  expect_issue(c.doc, c.key, c.at, c.message);
}

const std::string kTrigger = "[trigger]\nbackend = \"simulated\"\n";

INSTANTIATE_TEST_SUITE_P(
    Config, RangeIssues,
    ::testing::Values(
        RangeCase{"ppp_zero", rig_with("", "[simulation]\nppp = 0\n"), "simulation.ppp", "ppp", "0 must be in (0, 1]"},
        RangeCase{"ppp_above_one", rig_with("", "[simulation]\nppp = 1.5\n"), "simulation.ppp", "ppp",
                  "1.5 must be in (0, 1]"},
        RangeCase{"rate_zero", rig_with("", kTrigger + "rate_hz = 0\n"), "trigger.rate_hz", "rate_hz", "0 must be > 0"},
        RangeCase{"dt_negative", rig_with("", kTrigger + "dt_us = -1\n"), "trigger.dt_us", "dt_us", "-1 must be > 0"},
        RangeCase{"pulse_zero", rig_with("", kTrigger + "pulse_width_us = 0\n"), "trigger.pulse_width_us",
                  "pulse_width_us", "0 must be > 0"},
        RangeCase{"jitter_negative", rig_with("", kTrigger + "jitter_ns = -2\n"), "trigger.jitter_ns", "jitter_ns",
                  "-2 must be >= 0"},
        RangeCase{"dt_longer_than_period", rig_with("", kTrigger + "rate_hz = 10\ndt_us = 200000\n"),
                  "trigger.dt_us", "dt_us", "200000 must be < the trigger period 1/rate_hz (100000 us)"},
        RangeCase{"pulse_longer_than_dt", rig_with("", kTrigger + "dt_us = 10\npulse_width_us = 20\n"),
                  "trigger.pulse_width_us", "pulse_width_us", "20 must be < dt_us (10)"},
        RangeCase{"trigger_backend", rig_with("", "[trigger]\nbackend = \"usb\"\n"), "trigger.backend", "usb",
                  "\"usb\" must be one of gpio, simulated"},
        RangeCase{"channel_role", rig_with("", kTrigger + "[[trigger.channels]]\nname = \"x\"\nrole = \"laser\"\n"),
                  "trigger.channels[0].role", "laser", "\"laser\" must be one of light, camera"},
        RangeCase{"channel_line", rig_with("", kTrigger + "[[trigger.channels]]\nname = \"x\"\nrole = \"light\"\nline = -3\n"),
                  "trigger.channels[0].line", "line = -3", "-3 must be >= 0"},
        RangeCase{"grid_nx", rig_with("", "[grid]\nnx = 0\n"), "grid.nx", "nx", "0 must be > 0"},
        RangeCase{"grid_ny", rig_with("", "[grid]\nny = -4\n"), "grid.ny", "ny", "-4 must be > 0"},
        RangeCase{"grid_nz", rig_with("", "[grid]\nnz = 0\n"), "grid.nz", "nz", "0 must be > 0"},
        RangeCase{"grid_too_big", rig_with("", "[grid]\nnx = 100000\nny = 100000\nnz = 1\n"), "grid.nz", "nz",
                  "exceeds the supported 4294967295"},
        RangeCase{"voxel_size", rig_with("", "[grid]\nvoxel_size_mm = 0.0\n"), "grid.voxel_size_mm", "voxel_size_mm",
                  "0 must be > 0"},
        RangeCase{"roi_width", rig_with("", "", "width = 0\nheight = 4\n"), "cameras[0].roi.width", "width = 0",
                  "0 must be > 0"},
        RangeCase{"roi_height", rig_with("", "", "width = 4\nheight = -1\n"), "cameras[0].roi.height", "height",
                  "-1 must be > 0"},
        RangeCase{"roi_offset", rig_with("", "", "offset_x = -1\nwidth = 4\nheight = 4\n"), "cameras[0].roi.offset_x",
                  "offset_x", "-1 must be >= 0"},
        RangeCase{"bit_depth", rig_with("", "[simulation]\nbit_depth = 14\n"), "simulation.bit_depth", "bit_depth",
                  "14 must be one of 12, 16"},
        RangeCase{"pixel_pitch", rig_with("pixel_pitch_um = 0"), "cameras[0].pixel_pitch_um", "pixel_pitch_um",
                  "0 must be > 0"},
        RangeCase{"sets", rig_with("", "[simulation]\nsets = 0\n"), "simulation.sets", "sets", "0 must be >= 1"},
        RangeCase{"distance_inside_focal_length", rig_with("focal_length_mm = 100\ndistance_mm = 50"),
                  "cameras[0].distance_mm", "distance_mm", "50 must be > focal_length_mm (100)"},
        RangeCase{"focal_length", rig_with("focal_length_mm = -5"), "cameras[0].focal_length_mm", "focal_length_mm",
                  "-5 must be > 0"},
        RangeCase{"yaw", rig_with("yaw_deg = 270"), "cameras[0].yaw_deg", "yaw_deg", "270 must be in [-180, 180]"},
        RangeCase{"camera_backend", rig_with("", "[[cameras]]\nid = \"b\"\nbackend = \"gige\"\n"),
                  "cameras[1].backend", "gige", "\"gige\" must be one of aravis, simulated, gentl"},
        RangeCase{"producer_on_aravis",
                  rig_with("", "[[cameras]]\nid = \"g\"\nbackend = \"aravis\"\ndevice_id = \"d\"\nproducer = \"x.cti\"\n"),
                  "cameras[1].producer", "producer", "is for backend = \"gentl\" cameras"},
        RangeCase{"empty_id", rig_with("", "[[cameras]]\nid = \"\"\nbackend = \"aravis\"\ndevice_id = \"d\"\n"),
                  "cameras[1].id", "id = \"\"", "\"\" must not be empty"},
        RangeCase{"algorithm", rig_with("", "[processing]\nalgorithm = \"art\"\n"), "processing.algorithm", "art",
                  "\"art\" must be one of mlos, ment, mart, smart, fmart"},
        RangeCase{"iterations", rig_with("", "[processing]\niterations = 0\n"), "processing.iterations", "iterations",
                  "0 must be >= 1"},
        RangeCase{"light_sheet", rig_with("", "[simulation]\nlight_sheet = \"flat\"\n"), "simulation.light_sheet",
                  "flat", "\"flat\" must be one of uniform, gaussian, tophat"},
        RangeCase{"case", rig_with("", "[simulation]\ncase = \"piv\"\n"), "simulation.case", "piv",
                  "\"piv\" must be one of tpiv-thesis"},
        RangeCase{"read_noise", rig_with("", "[simulation]\nread_noise_e = -1\n"), "simulation.read_noise_e",
                  "read_noise_e", "-1 must be >= 0"},
        RangeCase{"peak_counts", rig_with("", "[simulation]\npeak_counts = 0\n"), "simulation.peak_counts",
                  "peak_counts", "0 must be > 0"},
        RangeCase{"peak_above_full_scale", rig_with("", "[simulation]\nbit_depth = 12\npeak_counts = 5000\n"),
                  "simulation.peak_counts", "peak_counts", "5000 must be <= 4095, the full scale of bit_depth 12"},
        RangeCase{"calibration_file", rig_with("", "[calibration]\nfile = \"\"\n"), "calibration.file", "file",
                  "must not be empty"}),
    [](const ::testing::TestParamInfo<RangeCase>& info) { return std::string(info.param.name); });

// A gentl camera needs its device; its producer path is kept for the camera to check.
TEST(RigIssues, GentlCamerasNeedADeviceIdAndKeepTheirProducer) {
  const auto issues = check_rig_config(rig_with("", "[[cameras]]\nid = \"g\"\nbackend = \"gentl\"\n"));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key, "cameras[1].device_id");
  EXPECT_NE(issues[0].message.find("required"), std::string::npos) << issues[0].message;
  const RigConfig rig = parse_rig_config(rig_with(
      "", "[[cameras]]\nid = \"g\"\nbackend = \"gentl\"\ndevice_id = \"CXP-1\"\nproducer = \"/opt/x/grabber.cti\"\n"));
  EXPECT_EQ(rig.cameras.at(1).backend, CameraBackend::gentl);
  EXPECT_EQ(rig.cameras.at(1).device_id, "CXP-1");
  EXPECT_EQ(rig.cameras.at(1).producer, std::filesystem::path("/opt/x/grabber.cti"));
  EXPECT_EQ(to_string(CameraBackend::gentl), "gentl");
}

TEST(RigIssues, AllIssuesAreCollectedInLineOrder) {
  const std::string doc = R"(name = "many problems"
[[cameras]]
id = "a"
backend = "simulated"
pixel_format = "Mono10"
[cameras.roi]
width = 0
height = 4
hieght = 4
[trigger]
backend = "simulated"
rate_hz = -1
[grid]
nx = "many"
[simulation]
ppp = 2
)";
  const auto issues = check_rig_config(doc, "rig.toml");
  ASSERT_EQ(issues.size(), 6u) << dump(issues);
  const char* keys[] = {"cameras[0].pixel_format", "cameras[0].roi.width", "cameras[0].roi.hieght",
                        "trigger.rate_hz", "grid.nx", "simulation.ppp"};
  const int lines[] = {5, 7, 9, 12, 14, 16};
  for (std::size_t i = 0; i < issues.size(); ++i) {
    EXPECT_EQ(issues[i].key, keys[i]);
    EXPECT_EQ(issues[i].line, lines[i]) << issues[i].to_string();
  }

  // parse_rig_config throws one bad_input error listing every issue, one per line.
  try {
    parse_rig_config(doc, "rig.toml");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    std::string expected = "rig.toml: 6 problems in the rig config:";
    for (const auto& issue : issues) expected += '\n' + issue.to_string();
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

TEST(ConfigIssue, ToStringFormats) {
  ConfigIssue issue;
  issue.origin = "rig.toml";
  issue.key = "grid.nx";
  issue.line = 3;
  issue.message = "0 must be > 0";
  EXPECT_EQ(issue.to_string(), "rig.toml:3: grid.nx: 0 must be > 0");
  issue.line = 0;
  EXPECT_EQ(issue.to_string(), "rig.toml: grid.nx: 0 must be > 0");
  issue.origin.clear();
  issue.line = 3;
  EXPECT_EQ(issue.to_string(), "line 3: grid.nx: 0 must be > 0");
  issue.origin = "rig.toml";
  issue.key.clear();
  issue.column = 7;
  issue.message = "invalid TOML: oops";
  EXPECT_EQ(issue.to_string(), "rig.toml:3:7: invalid TOML: oops");
}

TEST(ConfigEnums, ToString) {
  EXPECT_EQ(to_string(CameraBackend::aravis), "aravis");
  EXPECT_EQ(to_string(CameraBackend::simulated), "simulated");
  EXPECT_EQ(to_string(TriggerBackend::gpio), "gpio");
  EXPECT_EQ(to_string(TriggerBackend::simulated), "simulated");
}

// ---- loading files ------------------------------------------------------------------------

TEST(LoadRig, MissingFileNamesThePath) {
  const std::filesystem::path missing = std::filesystem::temp_directory_path() / "tomorig_no_such_rig.toml";
  try {
    load_rig_config(missing);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(LoadRig, DirectoryIsRejected) {
  TempDir dir;
  try {
    load_rig_config(dir.path());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(LoadRig, MessagesNameTheFile) {
  TempDir dir;
  const auto file = dir.write("bad.toml", rig_with("pixel_format = \"Mono14\""));
  try {
    load_rig_config(file);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(file.string() + ":4: cameras[0].pixel_format"), std::string::npos)
        << e.what();
  }
}

TEST(LoadRig, RelativeCalibrationIsNextToTheRigFile) {
  TempDir dir;
  const auto file = dir.write("rig.toml", rig_with("", "[calibration]\nfile = \"calib/cams.h5\"\n"));
  const RigConfig rig = load_rig_config(file);
  ASSERT_TRUE(rig.calibration_file.has_value());
  EXPECT_EQ(*rig.calibration_file, dir.path() / "calib/cams.h5");
  EXPECT_EQ(rig.source_text, read_file(file));
}

TEST(LoadRig, LoadsTheDefaultRig) {
  TempDir dir;
  const RigConfig rig = load_rig_config(dir.write("default.toml", default_rig_toml()));
  EXPECT_EQ(rig.cameras.size(), 4u);
}

}  // namespace
}  // namespace tomorig::config
