#pragma once
// Compares what two session files say besides their frames: /config, root attributes, the
// cameras' attributes (pixel pitch included) and the truth of simulated sessions. A split rig
// (acquire -> record) and a replay copy must match the file `tomorig run` or the source wrote.
#include <gtest/gtest.h>

#include <filesystem>

#include "tomorig/storage/session_file.h"

namespace tomorig::testing {

inline void expect_same_particles(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x) << where << " particle " << i;
    EXPECT_EQ(a[i].y, b[i].y) << where << " particle " << i;
    EXPECT_EQ(a[i].z, b[i].z) << where << " particle " << i;
  }
}

// `created_utc` is compared only when asked: a copy keeps the source's, a new recording has
// its own.
inline void expect_same_session_metadata(const std::filesystem::path& want_path, const std::filesystem::path& got_path,
                                         bool same_creation_time) {
  const storage::SessionReader want(want_path);
  const storage::SessionReader got(got_path);
  const storage::SessionInfo& a = want.info();
  const storage::SessionInfo& b = got.info();
  EXPECT_FALSE(a.rig_config_toml.empty());
  EXPECT_EQ(b.rig_config_toml, a.rig_config_toml);
  EXPECT_EQ(b.software_version, a.software_version);
  EXPECT_EQ(b.compression, a.compression);
  EXPECT_EQ(got.format_version(), want.format_version());
  EXPECT_EQ(got.recording_complete(), want.recording_complete());
  if (same_creation_time) {
    EXPECT_EQ(b.created_utc, a.created_utc);
  }
  ASSERT_EQ(b.cameras.size(), a.cameras.size());
  for (std::size_t c = 0; c < a.cameras.size(); ++c) {
    EXPECT_EQ(b.cameras[c].id, a.cameras[c].id);
    EXPECT_EQ(b.cameras[c].width, a.cameras[c].width);
    EXPECT_EQ(b.cameras[c].height, a.cameras[c].height);
    EXPECT_EQ(b.cameras[c].pixel_format, a.cameras[c].pixel_format);
    EXPECT_GT(a.cameras[c].pixel_pitch_um, 0.0) << a.cameras[c].id;
    EXPECT_EQ(b.cameras[c].pixel_pitch_um, a.cameras[c].pixel_pitch_um) << a.cameras[c].id;
  }
  ASSERT_TRUE(want.has_truth());
  ASSERT_TRUE(got.has_truth()) << got_path << " lost the truth";
  const storage::SessionTruth ta = want.truth();
  const storage::SessionTruth tb = got.truth();
  EXPECT_EQ(tb.case_name, ta.case_name);
  EXPECT_EQ(tb.flow_name, ta.flow_name);
  EXPECT_EQ(tb.flow_parameters, ta.flow_parameters);
  EXPECT_EQ(tb.seed, ta.seed);
  EXPECT_EQ(tb.ppp, ta.ppp);
  ASSERT_EQ(tb.cameras.size(), ta.cameras.size());
  for (std::size_t c = 0; c < ta.cameras.size(); ++c) {
    EXPECT_EQ(tb.cameras[c].id, ta.cameras[c].id);
    EXPECT_EQ(tb.cameras[c].model, ta.cameras[c].model);
    EXPECT_EQ(tb.cameras[c].K, ta.cameras[c].K);
    EXPECT_EQ(tb.cameras[c].R, ta.cameras[c].R);
    EXPECT_EQ(tb.cameras[c].t.x, ta.cameras[c].t.x);
    EXPECT_EQ(tb.cameras[c].t.y, ta.cameras[c].t.y);
    EXPECT_EQ(tb.cameras[c].t.z, ta.cameras[c].t.z);
    EXPECT_EQ(tb.cameras[c].width, ta.cameras[c].width);
    EXPECT_EQ(tb.cameras[c].height, ta.cameras[c].height);
  }
  ASSERT_EQ(got.truth_set_count(), want.truth_set_count());
  for (std::uint64_t k = 0; k < want.set_count(); ++k) {
    ASSERT_EQ(got.has_truth_set(k), want.has_truth_set(k)) << "set " << k;
    if (!want.has_truth_set(k)) continue;
    const storage::TruthSet sa = want.truth_set(k);
    const storage::TruthSet sb = got.truth_set(k);
    expect_same_particles(sa.particles_a, sb.particles_a, "set " + std::to_string(k) + " A");
    expect_same_particles(sa.particles_b, sb.particles_b, "set " + std::to_string(k) + " B");
  }
}

}  // namespace tomorig::testing
