// The tracker's feature table: every observation of every track as CSV,
// `feature_id,frame,u,v`, so tracking can be inspected, plotted and re-used
// without re-running KLT.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "monomap/map/map.h"

namespace monomap {

// Header lines of the table: a comment naming the format, then the CSV
// column header.
inline constexpr const char* kFeatureTableComment = "# monomap feature table";
inline constexpr const char* kFeatureTableColumns = "feature_id,frame,u,v";

// Formats tracks as the table: the two header lines, then one row per
// observation in the order given (u, v are raw pixel coordinates, written in
// shortest round-trip form so reading gives back the same doubles).
std::string FormatFeatureTable(const std::vector<Track>& tracks);

// Writes the table atomically. Throws OutputError on failure.
void WriteFeatureTable(const std::filesystem::path& path,
                       const std::vector<Track>& tracks);
// The table written to `out` in pieces of about a megabyte, for a long
// sequence, whose table is over 100 MB (a whole string grown by doubling
// would need twice that).
void WriteFeatureTable(std::ostream& out, const std::vector<Track>& tracks);

// Reads a table back into tracks: tracks in order of first appearance, the
// observations of each sorted by frame. Blank lines and lines starting with
// '#' are ignored; the first other line must be the column header. Throws
// InputError naming file and line on a malformed row, a negative frame, a
// non-finite coordinate or an observation repeated for the same
// (feature_id, frame).
std::vector<Track> ReadFeatureTable(const std::filesystem::path& path);

}  // namespace monomap
