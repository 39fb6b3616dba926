#include "monomap/io/feature_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <ostream>
#include <unordered_map>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

// Shortest representation that parses back to the same double.
void AppendDouble(double value, std::string* out) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    fields.push_back(Trim(text.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

template <typename T>
bool ParseInteger(const std::string& token, T* value) {
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end && !token.empty();
}

std::string FeatureTableHeader() {
  return std::string(kFeatureTableComment) + "\n" + kFeatureTableColumns + "\n";
}

// Appends the rows of one track.
void AppendTrackRows(const Track& track, std::string* out) {
  const std::string id = std::to_string(track.id);
  for (const Observation& obs : track.observations) {
    *out += id;
    *out += ',';
    *out += std::to_string(obs.frame);
    *out += ',';
    AppendDouble(obs.px.x(), out);
    *out += ',';
    AppendDouble(obs.px.y(), out);
    *out += '\n';
  }
}

}  // namespace

std::string FormatFeatureTable(const std::vector<Track>& tracks) {
  std::string out = FeatureTableHeader();
  for (const Track& track : tracks) AppendTrackRows(track, &out);
  return out;
}

void WriteFeatureTable(const std::filesystem::path& path,
                       const std::vector<Track>& tracks) {
  WriteFileAtomic(path, FormatFeatureTable(tracks));
}

void WriteFeatureTable(std::ostream& out, const std::vector<Track>& tracks) {
  constexpr size_t kChunkBytes = 1 << 20;
  std::string chunk = FeatureTableHeader();
  for (const Track& track : tracks) {
    AppendTrackRows(track, &chunk);
    if (chunk.size() >= kChunkBytes) {
      out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      chunk.clear();
    }
  }
  out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
}

std::vector<Track> ReadFeatureTable(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::vector<TextLine> lines = ReadDataLines(path);
  if (lines.empty()) {
    throw InputError(file + ": empty feature table (expected header '" +
                     kFeatureTableColumns + "')");
  }
  if (Trim(lines[0].text) != kFeatureTableColumns) {
    throw InputError(file, lines[0].number,
                     std::string("expected column header '") +
                         kFeatureTableColumns + "', got '" +
                         Trim(lines[0].text) + "'");
  }
  std::vector<Track> tracks;
  std::unordered_map<FeatureId, size_t> index_of_id;
  // Line of each observation, to name both lines of a duplicate.
  std::vector<std::vector<int>> line_of_obs;
  for (size_t i = 1; i < lines.size(); ++i) {
    const TextLine& line = lines[i];
    const auto fields = SplitCommas(line.text);
    if (fields.size() != 4) {
      throw InputError(file, line.number,
                       "expected 4 comma-separated values "
                       "'feature_id,frame,u,v', got " +
                           std::to_string(fields.size()));
    }
    FeatureId id = 0;
    if (!ParseInteger(fields[0], &id)) {
      throw InputError(file, line.number,
                       "feature_id '" + fields[0] + "' is not an integer");
    }
    int frame = 0;
    if (!ParseInteger(fields[1], &frame) || frame < 0) {
      throw InputError(
          file, line.number,
          "frame '" + fields[1] + "' is not a non-negative integer");
    }
    Observation obs;
    obs.frame = frame;
    for (int k = 0; k < 2; ++k) {
      if (!ParseDouble(fields[2 + k], &obs.px[k])) {
        throw InputError(file, line.number,
                         std::string(k == 0 ? "u" : "v") + " '" +
                             fields[2 + k] + "' is not a finite number");
      }
    }
    auto [it, inserted] = index_of_id.try_emplace(id, tracks.size());
    if (inserted) {
      tracks.push_back(Track{id, {}});
      line_of_obs.emplace_back();
    }
    tracks[it->second].observations.push_back(obs);
    line_of_obs[it->second].push_back(line.number);
  }
  for (size_t t = 0; t < tracks.size(); ++t) {
    auto& observations = tracks[t].observations;
    std::vector<size_t> order(observations.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return observations[a].frame < observations[b].frame;
    });
    std::vector<Observation> sorted;
    sorted.reserve(order.size());
    for (size_t k = 0; k < order.size(); ++k) {
      if (k > 0 &&
          observations[order[k]].frame == observations[order[k - 1]].frame) {
        const int first = line_of_obs[t][std::min(order[k], order[k - 1])];
        const int second = line_of_obs[t][std::max(order[k], order[k - 1])];
        throw InputError(file, second,
                         "feature " + std::to_string(tracks[t].id) +
                             " observed twice in frame " +
                             std::to_string(observations[order[k]].frame) +
                             " (also on line " + std::to_string(first) + ")");
      }
      sorted.push_back(observations[order[k]]);
    }
    observations = std::move(sorted);
  }
  return tracks;
}

}  // namespace monomap
