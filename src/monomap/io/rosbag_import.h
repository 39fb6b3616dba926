// Imports a ROS 1 bag (read with Debian's librosbag-dev) into a dataset in
// monomap's layout; the messages, options and report are those of
// io/bag_import.h, which does everything but the reading.
#pragma once

#include <filesystem>

#include "monomap/io/bag_import.h"

namespace monomap {

// Reads `bag` and writes the dataset to `out_dir` atomically (replacing it
// only on success). Throws InputError naming the bag and the topic or field
// for a missing topic (listing the topics the bag has), a truncated or
// unreadable bag, an unsupported encoding or lens model, a missing
// calibration or mount; nothing is written then.
RosbagImportReport ImportRosbag(const std::filesystem::path& bag,
                                const std::filesystem::path& out_dir,
                                const RosbagImportOptions& options);

}  // namespace monomap
