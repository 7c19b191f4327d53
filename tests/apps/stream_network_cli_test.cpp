// The stream beyond loopback, through the commands (issue 14, item 6): a remote bind warns and
// requires a shared token, admits only peers presenting it and names the ones it refuses;
// tcp://localhost works for bind and connect; Ctrl-C on an acquire that waits for a recorder
// ends it at once.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include <zmq.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "scripted_sender.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::testing {
namespace {

using Clock = std::chrono::steady_clock;

// "record: receiving on tcp://0.0.0.0:40123, writing ..." -> "40123"
std::string port_in(const std::string& line) {
  const auto end = line.find(',');
  const auto colon = line.rfind(':', end);
  return line.substr(colon + 1, end - colon - 1);
}

class StreamNetworkCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  TempDir dir_;
  std::filesystem::path out_ = dir_ / "out.h5";
};

TEST_F(StreamNetworkCli, RemoteBindWithoutATokenIsRefusedNamingTheOptions) {
  for (const std::string command : {"record --bind --from tcp://0.0.0.0:0 -o " + shell_quoted(out_.string()),
                                    std::string("acquire --sets 1 --to tcp://0.0.0.0:0")}) {
    const CliResult r = run_tomorig(command + " --allow-remote");
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("needs a shared token"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--token"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("TOMORIG_STREAM_TOKEN"), std::string::npos) << r.err;
  }
  // Without --allow-remote the refusal names the flag the command has (not a setting that
  // does not exist).
  const CliResult r = run_tomorig("record --bind --from tcp://0.0.0.0:0 -o " + shell_quoted(out_.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("give --allow-remote"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("allow_remote = true"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out_));
}

TEST_F(StreamNetworkCli, RemoteRecorderWarnsAdmitsTheTokenAndNamesARefusedPeer) {
  TomorigProcess record({"record", "--bind", "--from", "tcp://0.0.0.0:*", "--allow-remote", "--token", "s3cret", "-o",
                         out_.string(), "--sets", "2", "--idle-timeout", "60"});
  const auto warning = record.wait_for_line("WARNING: stream endpoint");
  ASSERT_TRUE(warning) << record.err();
  EXPECT_NE(warning->find("accepts connections from other hosts"), std::string::npos) << *warning;
  const auto line = record.wait_for_line("record: receiving on");
  ASSERT_TRUE(line) << record.err();
  const std::string endpoint = "tcp://127.0.0.1:" + port_in(*line);

  {  // a sender with the wrong token: refused at the handshake, counted and named
    zmq::context_t context;
    stream::SocketOptions o;
    o.endpoint = {endpoint, false, false, "--allow-remote", "guess"};
    o.timeout = std::chrono::milliseconds(500);
    stream::FrameSender wrong(context, o);
    // A connecting socket queues what it sends, but it is never admitted: nothing reaches record.
    EXPECT_TRUE(wrong.send(small_set(7)));
    EXPECT_FALSE(wrong.wait_for_receiver(std::chrono::milliseconds(500)));
    const auto refused = record.wait_for_line("refused a connection from 127.0.0.1: wrong token");
    ASSERT_TRUE(refused) << record.err();
  }
  zmq::context_t context;
  stream::SocketOptions o;
  o.endpoint = {endpoint, false, false, "--allow-remote", "s3cret"};
  o.timeout = std::chrono::seconds(30);
  stream::FrameSender right(context, o);
  ASSERT_TRUE(right.send(small_set(0)));
  ASSERT_TRUE(right.send(small_set(1)));
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_NE(record.out().find("recorded 2 sets"), std::string::npos) << record.out();
  EXPECT_NE(record.out().find("refused for a wrong token (last from 127.0.0.1)"), std::string::npos) << record.out();
  const storage::SessionReader session(out_);
  ASSERT_EQ(session.set_count(), 2u);
  EXPECT_EQ(session.set_record(0).trigger_index, 100u);  // small_set(0), not the refused sender's set 7
  EXPECT_EQ(session.set_record(1).trigger_index, 101u);
}

// ZeroMQ binds interface names, and "localhost" is none: it used to pass the loopback check
// and then fail with "No such device".
TEST_F(StreamNetworkCli, LocalhostWorksForBindAndConnect) {
  TomorigProcess record({"record", "--bind", "--from", "tcp://localhost:*", "-o", out_.string(), "--sets", "1",
                         "--idle-timeout", "60"});
  const auto line = record.wait_for_line("record: receiving on");
  ASSERT_TRUE(line) << record.err();
  EXPECT_NE(line->find("tcp://127.0.0.1:"), std::string::npos) << *line;
  zmq::context_t context;
  stream::SocketOptions o;
  o.endpoint = {"tcp://localhost:" + port_in(*line), false};
  o.timeout = std::chrono::seconds(30);
  stream::FrameSender sender(context, o);
  ASSERT_TRUE(sender.send(small_set(0)));
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_EQ(storage::SessionReader(out_).set_count(), 1u);
}

// A port nobody listens on: bound by the test, then released.
std::string free_port() {
  zmq::context_t context;
  zmq::socket_t probe(context, zmq::socket_type::pull);
  probe.bind("tcp://127.0.0.1:*");
  const std::string endpoint = probe.get(zmq::sockopt::last_endpoint);
  return endpoint.substr(endpoint.rfind(':') + 1);
}

// Ctrl-C while acquire waits for its recorder ends it at once, nothing acquired, exit 0 (docs/
// cli.md). Before: with --connect the session start was queued with nobody there, the trigger
// started, and Ctrl-C then waited out --timeout for the set in hand (10 s each) and exited 1.
TEST_F(StreamNetworkCli, CtrlCOnAcquireWaitingForARecorderEndsItAtOnce) {
  for (const bool connect : {false, true}) {
    std::vector<std::string> args{"acquire", "--sets", "20", "--status", "none", "--wait", "60", "--timeout", "30"};
    if (connect) {
      args.insert(args.end(), {"--connect", "--to", "tcp://127.0.0.1:" + free_port()});
    } else {
      args.insert(args.end(), {"--to", "tcp://127.0.0.1:*"});
    }
    TomorigProcess acquire(args);
    ASSERT_TRUE(acquire.wait_for_line(connect ? "acquire: connected to" : "acquire: sending on")) << acquire.err();
    const auto sent = Clock::now();
    acquire.send_signal(SIGINT);
    const int code = acquire.wait();
    const double seconds = std::chrono::duration<double>(Clock::now() - sent).count();
    EXPECT_EQ(code, 0) << (connect ? "--connect: " : "") << acquire.err();
    EXPECT_LT(seconds, 2.0) << "well under 1 s on a quiet machine; the old wait was --timeout per set (30 s)";
    EXPECT_NE(acquire.out().find("stopped by SIGINT before acquiring"), std::string::npos) << acquire.out();
    EXPECT_EQ(acquire.err().find("acquire: set 1/"), std::string::npos) << "nothing may be acquired: " << acquire.err();
  }
}

}  // namespace
}  // namespace tomorig::testing
