// `tomorig record` against a scripted sender (the stream library in the test process): what
// it does with the session messages when the stream is not a well-behaved acquire or replay.
// An older sender's stream without them still records; an end of acquisition announcing sets
// that never arrived fails the recording, with the file complete; a second session starting
// mid-recording ends it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <zmq.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/session_file.h"
#include "scripted_sender.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::testing {
namespace {
using namespace std::chrono_literals;

class RecordSession : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  TempDir dir_;
  std::filesystem::path out_ = dir_ / "out.h5";
};

TEST_F(RecordSession, StreamWithoutSessionMessagesIsStillRecorded) {
  ScriptedSender sender;
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--sets", "2"});
  ASSERT_TRUE(sender->send(small_set(0)));
  ASSERT_TRUE(sender->send(small_set(1)));
  ASSERT_EQ(record.wait(), 0) << record.err();
  const storage::SessionReader session(out_);
  EXPECT_EQ(session.set_count(), 2u);
  EXPECT_NE(session.info().rig_config_toml.find("announced no session"), std::string::npos)
      << session.info().rig_config_toml;
  EXPECT_EQ(session.info().cameras.at(0).pixel_pitch_um, 0.0);  // unknown without a session start
  EXPECT_FALSE(session.has_truth());
}

TEST_F(RecordSession, AnnouncedSessionEndsTheRecordingAndKeepsConfigAndPitch) {
  ScriptedSender sender;
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--idle-timeout", "60"});
  ASSERT_TRUE(sender->send(small_start(42)));
  ASSERT_TRUE(sender->send(small_set(0)));
  ASSERT_TRUE(sender->send(small_set(1)));
  stream::SessionEnd end{42, 2, stream::SessionOutcome::stopped, "stopped by SIGINT"};
  ASSERT_TRUE(sender->send(end));
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_NE(record.out().find("the sender ended the session: stopped (stopped by SIGINT)"), std::string::npos)
      << record.out();
  const storage::SessionReader session(out_);
  EXPECT_EQ(session.set_count(), 2u);
  EXPECT_EQ(session.info().rig_config_toml, "name = \"scripted\"\n");
  EXPECT_EQ(session.info().software_version, "scripted-sender");
  EXPECT_EQ(session.info().cameras.at(1).pixel_pitch_um, 5.5);
  EXPECT_TRUE(session.recording_complete());
}

TEST_F(RecordSession, SetsTheSenderSentButThatNeverArrivedFailTheRecording) {
  ScriptedSender sender;
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--idle-timeout", "60"});
  ASSERT_TRUE(sender->send(small_start(7)));
  ASSERT_TRUE(sender->send(small_set(0)));
  ASSERT_TRUE(sender->send(stream::SessionEnd{7, 3, stream::SessionOutcome::completed, ""}));
  EXPECT_EQ(record.wait(), 1) << record.err();
  EXPECT_NE(record.err().find("2 of the 3 sets the sender sent never arrived"), std::string::npos) << record.err();
  const storage::SessionReader session(out_);  // complete and readable with what arrived
  EXPECT_EQ(session.set_count(), 1u);
  EXPECT_TRUE(session.recording_complete());
}

TEST_F(RecordSession, AnotherSessionStartingMidRecordingEndsIt) {
  ScriptedSender sender;
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--idle-timeout", "60"});
  ASSERT_TRUE(sender->send(small_start(1)));
  ASSERT_TRUE(sender->send(small_set(0)));
  ASSERT_TRUE(sender->send(small_start(2)));
  EXPECT_EQ(record.wait(), 1) << record.err();
  EXPECT_NE(record.err().find("another session (0000000000000002) started"), std::string::npos) << record.err();
  const storage::SessionReader session(out_);
  EXPECT_EQ(session.set_count(), 1u);
  EXPECT_FALSE(std::filesystem::exists(out_.string() + ".partial"));
}

}  // namespace
}  // namespace tomorig::testing
