// `-o` never loses data: refusals, atomic replacement of a map, kills at the
// exact instants of a commit, SIGTERM, and two writers to one output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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
    root_ = new fs::path(fs::temp_directory_path() /
                         ("monomap_output_test_" + std::to_string(getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    SimulationOptions sim;
    sim.world = "lab-corner";
    sim.num_frames = kNewFrames;
    sim.width = 320;
    sim.height = 240;
    Simulate(sim, *root_ / "data");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  static fs::path Data() { return *root_ / "data"; }
  static std::vector<std::string> BuildArgs(const fs::path& out, int frames) {
    return {"build", Data().string(), "-o", out.string(), "-q", "--no-ba",
            "--frames", std::to_string(frames)};
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
  // Entries of the fixture folder other than the dataset, the logs and
  // `expected`.
  static std::set<std::string> Extra(const std::set<std::string>& expected) {
    std::set<std::string> extra;
    for (const auto& e : fs::directory_iterator(*root_)) {
      const std::string name = e.path().filename().string();
      if (name != "data" && e.path().extension() != ".log" &&
          !expected.count(name)) {
        extra.insert(name);
      }
    }
    return extra;
  }
  static fs::path* root_;
};
fs::path* OutputSafety::root_ = nullptr;

TEST_F(OutputSafety, RefusesWhatIsNotItsOwnOutput) {
  // An existing file.
  const fs::path file = *root_ / "notes.txt";
  std::ofstream(file) << "precious";
  RunResult r = Build(file, kOldFrames);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("notes.txt: exists and is a file"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(ReadFileToString(file), "precious");
  // A directory that is not a monomap map.
  const fs::path foreign = *root_ / "photos";
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
  r = RunMonomap("simulate lab-corner --frames 3 -q -o " + Data().string());
  EXPECT_EQ(r.exit_code, 0) << r.output;  // its own kind: replaced
  ASSERT_EQ(Build(*root_ / "map", kOldFrames).exit_code, 0);
  r = RunMonomap("simulate lab-corner --frames 3 -q -o " +
                 (*root_ / "map").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("is a monomap map directory, not a dataset"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(MapFrames(*root_ / "map"), kOldFrames);
  // The demo refuses a foreign folder before doing anything.
  r = RunMonomap("demo -q -o " + foreign.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(Extra({"notes.txt", "photos", "map"}), std::set<std::string>());
}

TEST_F(OutputSafety, ReplacesAPreviousMapAndLeavesNothingElse) {
  const fs::path out = *root_ / "map";
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
  const fs::path out = *root_ / "map";
  ASSERT_EQ(Build(out, kOldFrames).exit_code, 0);
  for (const std::string stage : {"before-swap", "after-swap"}) {
    SCOPED_TRACE(stage);
    const int before = MapFrames(out);
    const pid_t pid = test::SpawnMonomap(BuildArgs(out, kNewFrames),
                                         *root_ / (stage + ".log"),
                                         {"MONOMAP_TEST_STOP_AT=" + stage});
    ASSERT_TRUE(test::WaitUntilStopped(pid))
        << ReadFileToString(*root_ / (stage + ".log"));
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
  const fs::path out = *root_ / "map";
  ASSERT_EQ(Build(out, kOldFrames).exit_code, 0);
  const pid_t pid = test::SpawnMonomap(BuildArgs(out, kNewFrames),
                                       *root_ / "term.log",
                                       {"MONOMAP_TEST_STOP_AT=before-swap"});
  ASSERT_TRUE(test::WaitUntilStopped(pid));
  kill(pid, SIGTERM);
  kill(pid, SIGCONT);
  EXPECT_EQ(test::WaitForExit(pid), 128 + SIGTERM)
      << ReadFileToString(*root_ / "term.log");
  const int frames = MapFrames(out);
  EXPECT_TRUE(frames == kOldFrames || frames == kNewFrames) << frames;
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

// A second build to the same output waits for the first one's lock; when
// the first dies, the second cleans up after it and commits.
TEST_F(OutputSafety, ConcurrentWritersAreSerialized) {
  const fs::path out = *root_ / "map";
  const pid_t first = test::SpawnMonomap(BuildArgs(out, kOldFrames),
                                         *root_ / "first.log",
                                         {"MONOMAP_TEST_STOP_AT=before-swap"});
  ASSERT_TRUE(test::WaitUntilStopped(first));
  const fs::path second_log = *root_ / "second.log";
  const pid_t second =
      test::SpawnMonomap(BuildArgs(out, kNewFrames), second_log);
  bool waited = false;
  for (int i = 0; i < 6000 && !waited; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    waited = ReadFileToString(second_log).find("waiting for another") !=
             std::string::npos;
  }
  EXPECT_TRUE(waited) << ReadFileToString(second_log);
  kill(first, SIGKILL);
  EXPECT_EQ(test::WaitForExit(first), 128 + SIGKILL);
  EXPECT_EQ(test::WaitForExit(second), 0) << ReadFileToString(second_log);
  EXPECT_EQ(MapFrames(out), kNewFrames);
  EXPECT_EQ(Extra({"map"}), std::set<std::string>());
}

}  // namespace
}  // namespace monomap
