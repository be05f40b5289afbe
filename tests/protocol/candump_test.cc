// candump log writer/reader: exact line format, round trip, flushing, malformed lines, and a
// conversion of a written log by can-utils' log2asc (an independent reader of the format).
#include "protocol/candump.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"
#include "protocol/candump_replay_bus.h"
#include "protocol/messages.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

std::string TempPath(const std::string& name) {
  static const testing::ScopedTempDir tmp("candump");  // the suite's folder, removed at exit
  return tmp.File(name);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CanFrame Frame(uint16_t id, std::vector<uint8_t> bytes, double t) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<uint8_t>(bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) f.data[i] = bytes[i];
  f.t = t;
  return f;
}

TEST(Candump, LineFormat) {
  EXPECT_EQ(FormatCandumpLine(Frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF}, 0.123456), "can0", 1700000000),
            "(1700000000.123456) can0 123#DEADBEEF");
  EXPECT_EQ(FormatCandumpLine(Frame(0x7FF, {}, 2.5), "vcan1", 0), "(2.500000) vcan1 7FF#");
  EXPECT_EQ(FormatCandumpLine(Frame(0x00A, {0x01}, 0.0000004), "can0", 10), "(10.000000) can0 00A#01");
  CanFrame err;
  err.error = true;
  err.t = 1e-6;
  EXPECT_EQ(FormatCandumpLine(err, "can0", 0), "(0.000001) can0 20000080#0000000000000000");
}

TEST(Candump, RoundTripAndFlushEveryLine) {
  const std::string path = TempPath("rt.log");
  std::vector<CanFrame> frames = {Frame(0x010, {2, 0x81, 2, 7, 200}, 0.000053),
                                  Frame(0x181, {0xC0, 0xBD, 0xF0, 0xFF, 0x37, 0x03, 0x09, 42}, 0.001234),
                                  Frame(0x7FF, {}, 1.5)};
  CanFrame err;
  err.error = true;
  err.t = 2.000001;
  frames.push_back(err);
  {
    CandumpWriter w(path, "can0", 1700000000);
    for (size_t i = 0; i < frames.size(); ++i) {
      w.Write(frames[i]);
      // Flushed: the line is in the file while the writer is still open.
      const std::string text = ReadFile(path);
      EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), static_cast<long>(i + 1));
    }
    EXPECT_EQ(w.lines(), 4);
  }
  const std::vector<CandumpRecord> back = CandumpReader::ReadAll(path, 1700000000);
  ASSERT_EQ(back.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_TRUE(SamePayload(back[i].frame, frames[i])) << i;
    EXPECT_NEAR(back[i].frame.t, frames[i].t, 1e-9) << i;
    EXPECT_EQ(back[i].interface, "can0");
  }
  std::remove(path.c_str());
}

TEST(Candump, ReaderAcceptsCandumpVariants) {
  const std::string path = TempPath("var.log");
  std::ofstream(path) << "(1700000000.5) can1 1ab#0102\r\n\n  (0.000010) vcan0 000#   \n";
  const auto recs = CandumpReader::ReadAll(path);
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[0].frame.id, 0x1AB);
  EXPECT_EQ(recs[0].frame.dlc, 2);
  EXPECT_EQ(recs[0].frame.data[1], 0x02);
  EXPECT_DOUBLE_EQ(recs[0].frame.t, 1700000000.5);
  EXPECT_EQ(recs[1].interface, "vcan0");
  EXPECT_EQ(recs[1].frame.dlc, 0);
  std::remove(path.c_str());
}

TEST(Candump, MalformedLinesThrowWithLineNumber) {
  const std::vector<std::string> bad = {
      "1700000000.000001 can0 123#00",        // no parentheses
      "(1700000000) can0 123#00",             // no fraction
      "(17000x0000.000001) can0 123#00",      // not a number
      "(1700000000.000001) can0",             // no frame
      "(1700000000.000001) can0 12300",       // no '#'
      "(1700000000.000001) can0 123#0",       // odd hex digits
      "(1700000000.000001) can0 123#000102030405060708",  // 9 bytes
      "(1700000000.000001) can0 800#00",      // ID > 0x7FF
      "(1700000000.000001) can0 12345678#00", // extended ID
      "(1700000000.000001) can0 123#R",       // remote frame
      "(1700000000.000001) can0 123##100",    // CAN FD
      "(1700000000.000001) can0 12G#00",      // bad hex
  };
  for (const std::string& line : bad) {
    const std::string path = TempPath("bad.log");
    std::ofstream(path) << "(1.000000) can0 001#00\n\n" << line << "\n";
    try {
      CandumpReader::ReadAll(path);
      ADD_FAILURE() << "accepted: " << line;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ":3:"), std::string::npos) << e.what();
    }
    std::remove(path.c_str());
  }
  EXPECT_THROW(CandumpReader("/nonexistent/dir/x.log"), InputError);
  // The writer creates the log's missing folders (core/output_path.h); a file in their way is an InputError.
  const testing::ScopedTempDir tmp("candump_folders");
  std::ofstream(tmp.File("f")) << "x";
  EXPECT_THROW(CandumpWriter(tmp.File("f") + "/x.log"), InputError);
  { CandumpWriter w(tmp.path() + "/a/b/x.log"); }
  EXPECT_TRUE(std::ifstream(tmp.path() + "/a/b/x.log").good());
}

TEST(Candump, Log2AscConvertsOurLog) {
  const char* tool = "/usr/bin/log2asc";
  if (::access(tool, X_OK) != 0) GTEST_SKIP() << "can-utils log2asc not installed";
  const std::string path = TempPath("asc.log");
  std::map<uint16_t, int> sent;
  {
    CandumpWriter w(path, "can0", 1700000000);
    for (int k = 0; k < 20; ++k) {
      const double t = 0.001 * k;
      std::vector<CanFrame> fs = {msg::Encode(msg::ControllerHeartbeat{0, 0, 0, uint8_t(k)}),
                                  msg::Encode(msg::JointCommand{msg::Joint::kHip, 0.1 * k, uint8_t(k), true}),
                                  msg::Encode(msg::JointStatus{msg::Joint::kKnee, -0.01 * k, 0.3 * k, 1, uint8_t(k)}),
                                  msg::Encode(msg::EmgSamples{{0.1, -0.2, 0.3, -0.4, 0.5}, uint8_t(k % 16)})};
      for (CanFrame& f : fs) {
        f.t = t;
        w.Write(f);
        ++sent[f.id];
      }
    }
    CanFrame err;
    err.error = true;
    err.t = 0.5;
    w.Write(err);
  }
  const std::string cmd = std::string(tool) + " -I " + path + " can0 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ASSERT_EQ(::pclose(p), 0) << out;
  // ASC data lines: "<time> <channel> <ID> Rx d <dlc> <bytes...>"; error frames: "... ErrorFrame".
  std::map<uint16_t, int> seen;
  int errors = 0, lines = 0;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string time, chan, id, dir, d;
    int dlc = -1;
    if (!(ls >> time >> chan >> id)) continue;
    if (id == "ErrorFrame") {
      ++errors;
      continue;
    }
    if (!(ls >> dir >> d >> dlc) || dir != "Rx" || d != "d") continue;
    ++lines;
    ++seen[static_cast<uint16_t>(std::stoul(id, nullptr, 16))];
    int bytes = 0;
    std::string b;
    while (ls >> b) ++bytes;
    EXPECT_EQ(bytes, dlc) << line;
  }
  EXPECT_EQ(lines, 80);
  EXPECT_EQ(errors, 1);
  EXPECT_EQ(seen, sent);
  std::remove(path.c_str());
}

TEST(CandumpReplayBus, ReceivesLoggedFramesInSimulatedTime) {
  std::vector<CanFrame> frames = {Frame(0x180, {1}, 0.002), Frame(0x010, {2}, 0.001), Frame(0x200, {3}, 0.003)};
  CandumpReplayBus bus(frames, {0x010, 0x180});
  CanFrame f;
  EXPECT_EQ(bus.Receive(&f), CanStatus::kNoFrame);
  bus.SetTime(0.0025);
  ASSERT_EQ(bus.Receive(&f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x010);
  ASSERT_EQ(bus.Receive(&f), CanStatus::kOk);
  EXPECT_EQ(f.id, 0x180);
  EXPECT_EQ(bus.Receive(&f), CanStatus::kNoFrame);
  bus.SetTime(1.0);
  EXPECT_EQ(bus.Receive(&f), CanStatus::kNoFrame);  // 0x200 is filtered out
  EXPECT_EQ(bus.Send(Frame(0x100, {9, 9}, 0)), CanStatus::kOk);
  EXPECT_EQ(bus.Send(Frame(0x800, {}, 0)), CanStatus::kError);
  ASSERT_EQ(bus.sent().size(), 1u);
  EXPECT_EQ(bus.sent()[0].t, 1.0);
}

}  // namespace
}  // namespace exotwin
