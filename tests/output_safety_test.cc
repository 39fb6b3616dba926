// `-o` never loses data: refusals, atomic replacement of a map, kills at the
// exact instants of a commit, SIGTERM, and two writers to one output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "monomap/io/map_format.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/file.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using test::RunMonomap;
using test::RunResult;

constexpr int kOldFrames = 25;  // the map already at the target
constexpr int kNewFrames = 30;  // the map replacing it

class OutputSafety : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(
        test::FolderWithDataset("monomap_output_test", kNewFrames, 320, 240));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  // A fresh folder per test, so that the tests also pass in one process.
  void SetUp() override {
    dir_ = *root_ /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  static fs::path Data() { return *root_ / "data"; }
  static std::vector<std::string> BuildArgs(const fs::path& out, int frames) {
    return {"build", Data().string(), "-o",       out.string(),
            "-q",    "--no-ba",       "--frames", std::to_string(frames)};
  }
  static RunResult Build(const fs::path& out, int frames) {
    std::string line;
    for (const std::string& a : BuildArgs(out, frames)) line += a + " ";
    return RunMonomap(line);
  }
  // Frames of the complete map at `out`; -1 if there is none.
  static int MapFrames(const fs::path& out) {
    try {
      return static_cast<int>(ReadMap(out).trajectory.size());
    } catch (const std::exception&) {
      return -1;
    }
  }
  // Entries of the test's folder other than the logs and `expected`.
  std::set<std::string> Extra(const std::set<std::string>& expected) const {
    std::set<std::string> extra;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      if (e.path().extension() != ".log" && !expected.count(name)) {
        extra.insert(name);
      }
    }
    return extra;
  }
  static fs::path* root_;
  fs::path dir_;
};
fs::path* OutputSafety::root_ = nullptr;

TEST_F(OutputSafety, RefusesWhatIsNotItsOwnOutput) {
  // An existing file.
  const fs::path file = dir_ / "notes.txt";
  std::ofstream(file) << "precious";
  RunResult r = Build(file, kOldFrames);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("notes.txt: exists and is a file"), std::string::npos)
      << r.output;
  EXPECT_EQ(ReadFileToString(file), "precious");
  // A directory that is not a monomap map.
  const fs::path foreign = dir_ / "photos";
  fs::create_directories(foreign);
  std::ofstream(foreign / "a.jpg") << "precious";
  r = Build(foreign, kOldFrames);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("not a monomap map directory"), std::string::npos)
      << r.output;
  EXPECT_EQ(ReadFileToString(foreign / "a.jpg"), "precious");
  // The input dataset itself, and a folder inside it.
  for (const fs::path& out : {Data(), Data() / "map"}) {
    r = Build(out, kOldFrames);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("the input"), std::string::npos) << r.output;
  }
  EXPECT_TRUE(fs::exists(Data() / "rgb.txt"));
  EXPECT_FALSE(fs::exists(Data() / "map"));
  // A dataset is not replaced by a map, nor a map by a dataset.
  const std::string sim =
      "simulate lab-corner --frames 2 --width 64 --height 48 -q -o ";
  ASSERT_EQ(RunMonomap(sim + (dir_ / "sim").string()).exit_code, 0);
  r = RunMonomap(sim + (dir_ / "sim").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;  // its own kind: replaced
  ASSERT_EQ(Build(dir_ / "map", kOldFrames).exit_code, 0);
  r = RunMonomap(sim + (dir_ / "map").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is a monomap map directory, not a dataset"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(MapFrames(dir_ / "map"), kOldFrames);
  // The demo refuses a foreign folder before doing anything.
  r = RunMonomap("demo -q -o " + foreign.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(Extra({"notes.txt", "photos", "map", "sim"}),
            std::set<std::string>());
}

TEST_F(OutputSafety, ReplacesAPreviousMapAndLeavesNothingElse) {
  const fs::path out = dir_ / "map";
  ASSERT_EQ(Build(out, kOldFrames).exit_code, 0);
  EXPECT_EQ(MapFrames(out), kOldFrames);
  const RunResult r = Build(out, kNewFrames);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(MapFrames(out), kNewFrames);
  EXPECT_TRUE(fs::exists(out / kOutputMarkerFile));
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

// The process stops itself at each instant of the commit (test hook); the
// target holds a complete map there, and after a SIGKILL at that instant;
// the next run cleans up what the killed one left.
TEST_F(OutputSafety, AKillAtEachCommitStepKeepsACompleteMap) {
  const fs::path out = dir_ / "map";
  ASSERT_EQ(Build(out, kOldFrames).exit_code, 0);
  for (const std::string stage : {"before-swap", "after-swap"}) {
    SCOPED_TRACE(stage);
    const int before = MapFrames(out);
    const pid_t pid =
        test::SpawnMonomap(BuildArgs(out, kNewFrames), dir_ / (stage + ".log"),
                           {"MONOMAP_TEST_STOP_AT=" + stage});
    ASSERT_TRUE(test::WaitUntilStopped(pid))
        << ReadFileToString(dir_ / (stage + ".log"));
    const int expected = stage == "before-swap" ? before : kNewFrames;
    EXPECT_EQ(MapFrames(out), expected);
    kill(pid, SIGKILL);
    EXPECT_EQ(test::WaitForExit(pid), 128 + SIGKILL);
    EXPECT_EQ(MapFrames(out), expected);
    // The killed run left its temporary (new or old map) behind.
    EXPECT_EQ(Extra({"map"}).size(), 1u);
  }
  const RunResult r = Build(out, kOldFrames);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(MapFrames(out), kOldFrames);
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

// SIGTERM at the last moment before the swap: the run exits with 128 + 15,
// the target holds a complete map (old or new: the commit may win the race
// with the signal) and no temporary is left.
TEST_F(OutputSafety, SigtermCleansUpBeforeExiting) {
  const fs::path out = dir_ / "map";
  ASSERT_EQ(Build(out, kOldFrames).exit_code, 0);
  const pid_t pid =
      test::SpawnMonomap(BuildArgs(out, kNewFrames), dir_ / "term.log",
                         {"MONOMAP_TEST_STOP_AT=before-swap"});
  ASSERT_TRUE(test::WaitUntilStopped(pid));
  kill(pid, SIGTERM);
  kill(pid, SIGCONT);
  EXPECT_EQ(test::WaitForExit(pid), 128 + SIGTERM)
      << ReadFileToString(dir_ / "term.log");
  const int frames = MapFrames(out);
  EXPECT_TRUE(frames == kOldFrames || frames == kNewFrames) << frames;
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

// A second build to the same output waits for the first one's lock; when
// the first dies, the second cleans up after it and commits.
TEST_F(OutputSafety, ConcurrentWritersAreSerialized) {
  const fs::path out = dir_ / "map";
  const pid_t first =
      test::SpawnMonomap(BuildArgs(out, kOldFrames), dir_ / "first.log",
                         {"MONOMAP_TEST_STOP_AT=before-swap"});
  ASSERT_TRUE(test::WaitUntilStopped(first));
  const fs::path second_log = dir_ / "second.log";
  const pid_t second =
      test::SpawnMonomap(BuildArgs(out, kNewFrames), second_log);
  bool waited = false;
  for (int i = 0; i < 6000 && !waited; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    // The child creates its log after the fork: it may not be there yet.
    waited = fs::exists(second_log) &&
             ReadFileToString(second_log).find("waiting for another") !=
                 std::string::npos;
  }
  EXPECT_TRUE(waited) << ReadFileToString(second_log);
  kill(first, SIGKILL);
  EXPECT_EQ(test::WaitForExit(first), 128 + SIGKILL);
  EXPECT_EQ(test::WaitForExit(second), 0) << ReadFileToString(second_log);
  EXPECT_EQ(MapFrames(out), kNewFrames);
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

// --threads (oneTBB's global limit) changes the speed, not the map: every
// file is byte-identical at 1 and 2 threads. A bad value is a usage error.
TEST_F(OutputSafety, MapsAreByteIdenticalAtOneAndTwoThreads) {
  std::map<std::string, std::string> files[2];
  for (int threads : {1, 2}) {
    const fs::path out = dir_ / ("threads" + std::to_string(threads));
    const RunResult r =
        RunMonomap("build " + Data().string() + " -q -o " + out.string() +
                   " --threads " + std::to_string(threads));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (!e.is_regular_file()) continue;
      files[threads - 1][fs::relative(e.path(), out).string()] =
          ReadFileToString(e.path());
    }
  }
  EXPECT_GE(files[0].size(), 5u);
  ASSERT_EQ(files[0].size(), files[1].size());
  for (const auto& [name, bytes] : files[0]) {
    EXPECT_TRUE(files[1][name] == bytes) << name << " differs";
  }
  EXPECT_EQ(RunMonomap("build " + Data().string() + " -q -o " +
                       (dir_ / "t0").string() + " --threads 0")
                .exit_code,
            2);
}

}  // namespace
}  // namespace monomap
