#include "monomap/io/ros2_messages.h"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include <cmath>

#include "monomap/util/error.h"

namespace monomap::ros2 {
namespace {
namespace cdr = eprosima::fastcdr;

// One message being decoded: fastcdr's deserializer over the bytes, with
// the field being read kept for error messages.
class Reader {
 public:
  Reader(const uint8_t* data, size_t size, const std::string& where)
      : buffer_(reinterpret_cast<char*>(const_cast<uint8_t*>(data)), size),
        cdr_(buffer_, cdr::Cdr::DEFAULT_ENDIAN, cdr::Cdr::DDS_CDR),
        size_(size),
        where_(where) {
    // Byte 0 is 0, byte 1 the kind: 0 CDR big-endian, 1 CDR little-endian
    // (what ROS 2 writes); 2/3 are parameter lists, others XCDR2.
    if (size < 4 || data[0] != 0 || data[1] > 1) {
      throw InputError(where_, "encapsulation",
                       size < 4
                           ? "message of " + std::to_string(size) +
                                 " bytes is "
                                 "truncated"
                           : "kind " + std::to_string(data[0] * 256 + data[1]) +
                                 " is not plain CDR (0 or 1)");
    }
    try {
      cdr_.read_encapsulation();  // sets the endianness, resets alignment
    } catch (const cdr::exception::Exception& e) {
      throw InputError(where_, "encapsulation", e.what());
    }
  }

  template <typename T>
  T Read(const char* field) {
    field_ = field;
    T value{};
    cdr_.deserialize(value);
    return value;
  }
  void ReadDoubles(const char* field, double* out, size_t n) {
    field_ = field;
    cdr_.deserializeArray(out, n);
  }
  // sequence<T>: a uint32 length, then the elements; the length is checked
  // against the bytes left before anything is allocated.
  template <typename T>
  std::vector<T> ReadSequence(const char* field) {
    const uint32_t n = Read<uint32_t>(field);
    if (n > Remaining() / sizeof(T)) {
      throw InputError(where_, field,
                       "sequence of " + std::to_string(n) + " elements but " +
                           std::to_string(Remaining()) +
                           " bytes left "
                           "(truncated?)");
    }
    std::vector<T> v(n);
    if (n > 0) cdr_.deserializeArray(v.data(), n);
    return v;
  }
  // std_msgs/Header: stamp (int32 sec, uint32 nanosec), frame_id. A zero
  // stamp falls back to the recording time.
  double Header(double recorded, std::string* frame_id) {
    const int32_t sec = Read<int32_t>("header.stamp.sec");
    const uint32_t nanosec = Read<uint32_t>("header.stamp.nanosec");
    *frame_id = Read<std::string>("header.frame_id");
    return sec == 0 && nanosec == 0 ? recorded : sec + nanosec * 1e-9;
  }
  // geometry_msgs Vector3/Point (x, y, z) then Quaternion (x, y, z, w).
  Rigid3d Pose(const char* field) {
    double v[7];
    ReadDoubles(field, v, 7);
    const Eigen::Vector4d q(v[3], v[4], v[5], v[6]);
    if (!std::isfinite(v[0] + v[1] + v[2]) || !q.allFinite() ||
        q.norm() < 1e-6) {
      throw InputError(where_, field,
                       "not a finite pose with a non-zero quaternion");
    }
    return Rigid3d(Eigen::Quaterniond(v[6], v[3], v[4], v[5]),
                   Eigen::Vector3d(v[0], v[1], v[2]));
  }
  const std::string& Field() const { return field_; }

 private:
  size_t Remaining() {
    return size_ - static_cast<size_t>(cdr_.getCurrentPosition() -
                                       cdr_.getBufferPointer());
  }
  cdr::FastBuffer buffer_;
  cdr::Cdr cdr_;
  size_t size_;
  std::string where_;
  std::string field_ = "encapsulation";
};

// Runs `decode` and turns fastcdr's exceptions (reading past the end,
// bad parameters) into InputError naming the field.
template <typename F>
auto Decode(const uint8_t* data, size_t size, const std::string& where,
            F decode) {
  Reader r(data, size, where);
  try {
    return decode(r);
  } catch (const cdr::exception::Exception& e) {
    throw InputError(where, r.Field(),
                     "truncated or corrupt message (" + std::to_string(size) +
                         " bytes): " + e.what());
  }
}

}  // namespace

bag::Image DecodeImage(const uint8_t* data, size_t size, bool compressed,
                       double recorded, const std::string& where) {
  return Decode(data, size, where, [&](Reader& r) {
    bag::Image m;
    m.compressed = compressed;
    m.stamp = r.Header(recorded, &m.frame_id);
    if (compressed) {
      m.encoding = r.Read<std::string>("format");
    } else {
      m.height = r.Read<uint32_t>("height");
      m.width = r.Read<uint32_t>("width");
      m.encoding = r.Read<std::string>("encoding");
      if (r.Read<uint8_t>("is_bigendian") > 1) {
        throw InputError(where, "is_bigendian", "is neither 0 nor 1");
      }
      m.step = r.Read<uint32_t>("step");
    }
    m.data = r.ReadSequence<uint8_t>("data");
    return m;
  });
}

bag::CameraInfo DecodeCameraInfo(const uint8_t* data, size_t size,
                                 const std::string& where) {
  return Decode(data, size, where, [&](Reader& r) {
    bag::CameraInfo m;
    std::string frame;
    r.Header(0.0, &frame);
    m.height = r.Read<uint32_t>("height");
    m.width = r.Read<uint32_t>("width");
    m.distortion_model = r.Read<std::string>("distortion_model");
    m.d = r.ReadSequence<double>("d");
    r.ReadDoubles("k", m.k.data(), 9);
    // r, p, binning and roi follow; the importer does not need them.
    return m;
  });
}

std::vector<bag::Transform> DecodeTfMessage(const uint8_t* data, size_t size,
                                            double recorded,
                                            const std::string& where) {
  return Decode(data, size, where, [&](Reader& r) {
    const uint32_t n = r.Read<uint32_t>("transforms");
    // Each TransformStamped is at least 72 bytes: never trust a corrupt
    // count with an allocation.
    if (n > size / 72) {
      throw InputError(where, "transforms",
                       std::to_string(n) + " transforms in " +
                           std::to_string(size) + " bytes (corrupt)");
    }
    std::vector<bag::Transform> v(n);
    for (bag::Transform& t : v) {
      t.stamp = r.Header(recorded, &t.parent);
      t.child = r.Read<std::string>("child_frame_id");
      t.parent_from_child = r.Pose("transform");
    }
    return v;
  });
}

bag::Transform DecodeOdometry(const uint8_t* data, size_t size, double recorded,
                              const std::string& where) {
  return Decode(data, size, where, [&](Reader& r) {
    bag::Transform t;
    t.stamp = r.Header(recorded, &t.parent);
    t.child = r.Read<std::string>("child_frame_id");
    t.parent_from_child = r.Pose("pose.pose");
    // pose.covariance and the twist follow; not needed.
    return t;
  });
}

}  // namespace monomap::ros2
