// Imports a ROS 2 bag in the sqlite3 storage (a directory holding
// metadata.yaml and .db3 files, as `ros2 bag record` writes it) into a
// dataset in monomap's layout. The messages (CDR-serialized) are decoded
// here over Debian's libfastcdr and read with libsqlite3; everything else
// (options, report, interpolation, mount, dataset) is io/bag_import.h,
// shared with the ROS 1 importer.
#pragma once

#include <filesystem>

#include "monomap/io/bag_import.h"

namespace monomap {

// True if `path` looks like a ROS 2 bag: a directory with metadata.yaml or
// .db3 files, a metadata.yaml, or a .db3 file.
bool IsRosbag2(const std::filesystem::path& path);

// Reads the bag at `path` (any form IsRosbag2 accepts; a lone .db3 needs
// no metadata.yaml) and writes the dataset to `out_dir` atomically. Throws
// InputError naming the file and the topic or field for: a missing topic
// (listing the topics the bag has), a storage other than sqlite3 (e.g.
// mcap), compression, a serialization other than cdr, a truncated or
// corrupt .db3 or message, an unsupported encoding or lens model, a missing
// calibration or mount; nothing is written then.
RosbagImportReport ImportRosbag2(const std::filesystem::path& path,
                                 const std::filesystem::path& out_dir,
                                 const RosbagImportOptions& options);

}  // namespace monomap
