#include "monomap/io/feature_table.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

fs::path TempFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "monomap_feature_table";
  fs::create_directories(dir);
  return dir / name;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// Expects ReadFeatureTable to throw InputError containing every needle.
void ExpectReadError(const fs::path& path,
                     const std::vector<std::string>& needles) {
  try {
    ReadFeatureTable(path);
    FAIL() << "no error for " << path;
  } catch (const InputError& e) {
    for (const auto& needle : needles) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
          << "message '" << e.what() << "' lacks '" << needle << "'";
    }
  }
}

// The streamed table is the formatted one, byte for byte, also when it
// spans several of the 1 MB pieces (60,000 rows of ~40 bytes).
TEST(FeatureTableTest, StreamedTableEqualsTheFormattedOne) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(0.0, 640.0);
  std::vector<Track> tracks(600);
  for (size_t i = 0; i < tracks.size(); ++i) {
    tracks[i].id = 7 * i;
    for (int f = 0; f < 100; ++f) {
      tracks[i].observations.push_back({f, {coord(rng), coord(rng)}});
    }
  }
  std::ostringstream out;
  WriteFeatureTable(out, tracks);
  const std::string formatted = FormatFeatureTable(tracks);
  EXPECT_GT(formatted.size(), 2u << 20);
  EXPECT_EQ(out.str().size(), formatted.size());
  EXPECT_TRUE(out.str() == formatted);
}

TEST(FeatureTableTest, RoundTripIsExact) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-0.5, 751.5);
  std::vector<Track> tracks;
  // Ids out of order and one beyond 32 bits: the table keeps them as is.
  for (FeatureId id : {FeatureId{42}, FeatureId{3}, FeatureId{5000000000}}) {
    Track t;
    t.id = id;
    for (int f = static_cast<int>(id % 7); f < id % 7 + 20; ++f) {
      t.observations.push_back({f, {coord(rng), coord(rng)}});
    }
    tracks.push_back(t);
  }
  tracks[1].observations[3].px = {0.1 + 0.2, 1e-17};  // awkward doubles
  const fs::path path = TempFile("round_trip.csv");
  WriteFeatureTable(path, tracks);

  const std::string text = ReadFileToString(path);
  EXPECT_EQ(text.rfind("# monomap feature table\nfeature_id,frame,u,v\n", 0),
            0u);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2 + 3 * 20);

  const std::vector<Track> read = ReadFeatureTable(path);
  ASSERT_EQ(read.size(), tracks.size());
  for (size_t i = 0; i < tracks.size(); ++i) {
    EXPECT_EQ(read[i].id, tracks[i].id);
    ASSERT_EQ(read[i].observations.size(), tracks[i].observations.size());
    for (size_t k = 0; k < tracks[i].observations.size(); ++k) {
      EXPECT_EQ(read[i].observations[k].frame,
                tracks[i].observations[k].frame);
      // Bit-exact: shortest round-trip formatting.
      EXPECT_EQ(read[i].observations[k].px, tracks[i].observations[k].px);
    }
  }
}

TEST(FeatureTableTest, GroupsInterleavedRowsAndSortsByFrame) {
  const fs::path path = TempFile("interleaved.csv");
  WriteText(path,
            "# monomap feature table\nfeature_id,frame,u,v\n"
            "7,3,1.5,2.5\n9,1,10,20\n7,1,3,4\n\n7,2,5,6\n");
  const auto tracks = ReadFeatureTable(path);
  ASSERT_EQ(tracks.size(), 2u);
  EXPECT_EQ(tracks[0].id, 7);
  ASSERT_EQ(tracks[0].observations.size(), 3u);
  EXPECT_EQ(tracks[0].observations[0].frame, 1);
  EXPECT_EQ(tracks[0].observations[1].frame, 2);
  EXPECT_EQ(tracks[0].observations[2].frame, 3);
  EXPECT_EQ(tracks[0].observations[2].px, Eigen::Vector2d(1.5, 2.5));
  EXPECT_EQ(tracks[1].id, 9);
}

TEST(FeatureTableTest, MalformedLinesNameFileAndLine) {
  const std::string header = "# monomap feature table\nfeature_id,frame,u,v\n";
  const fs::path path = TempFile("bad.csv");
  WriteText(path, header + "1,0,10,20\n1,1,11,21\n1,2,abc,22\n");
  ExpectReadError(path, {"bad.csv:5:", "u 'abc'"});
  WriteText(path, header + "1,0,10,20\n1,1,11\n");
  ExpectReadError(path, {"bad.csv:4:", "expected 4"});
  WriteText(path, header + "1,-1,10,20\n");
  ExpectReadError(path, {"bad.csv:3:", "frame '-1'"});
  WriteText(path, header + "x1,0,10,20\n");
  ExpectReadError(path, {"bad.csv:3:", "feature_id 'x1'"});
  WriteText(path, header + "1,0,10,inf\n");
  ExpectReadError(path, {"bad.csv:3:", "v 'inf'"});
  WriteText(path, header + "1,4,10,20\n2,4,1,1\n1,4,11,21\n");
  ExpectReadError(path, {"bad.csv:5:", "twice in frame 4", "line 3"});
  WriteText(path, "1,0,10,20\n");
  ExpectReadError(path, {"bad.csv:1:", "column header"});
  WriteText(path, "# only a comment\n");
  ExpectReadError(path, {"bad.csv", "empty feature table"});
  ExpectReadError(TempFile("does_not_exist.csv"), {"does_not_exist.csv"});
}

}  // namespace
}  // namespace monomap
