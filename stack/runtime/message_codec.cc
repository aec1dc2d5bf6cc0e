#include "stack/runtime/message_codec.h"

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <type_traits>
#include <vector>

#include "stack/runtime/messages.h"

namespace adse::stack {
namespace {

// One field list per type, walked by both directions: Writer appends each
// field's bytes, Reader fills it back. Io(io, m) returns false only when a
// Reader runs out of bytes.
class Writer {
 public:
  explicit Writer(std::string* out) : out_(out) {}
  bool Bytes(const void* data, size_t n) {
    out_->append(static_cast<const char*>(data), n);
    return true;
  }
  // A count of elements of at least `min_bytes` each.
  bool Count(size_t& n, size_t /*min_bytes*/) {
    const uint64_t count = n;
    return Bytes(&count, sizeof count);
  }

 private:
  std::string* out_;
};

class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  bool Bytes(void* data, size_t n) {
    if (in_.size() - pos_ < n) return false;
    std::memcpy(data, in_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  // Refuses a count the remaining bytes cannot hold, before anything is
  // allocated for it.
  bool Count(size_t& n, size_t min_bytes) {
    uint64_t count = 0;
    if (!Bytes(&count, sizeof count)) return false;
    if (min_bytes > 0 && count > (in_.size() - pos_) / min_bytes) return false;
    n = static_cast<size_t>(count);
    return true;
  }
  size_t left() const { return in_.size() - pos_; }

 private:
  std::string_view in_;
  size_t pos_ = 0;
};

template <typename T>
constexpr bool kIsPlain = std::is_arithmetic_v<T> || std::is_enum_v<T>;
template <typename T>
struct IsFixedEigen : std::false_type {};
template <typename S, int R, int C, int O, int MR, int MC>
struct IsFixedEigen<Eigen::Matrix<S, R, C, O, MR, MC>>
    : std::bool_constant<(R > 0 && C > 0)> {};
// Copied as one block of bytes (fixed-size Eigen types hold only their
// coefficients).
template <typename T>
constexpr bool kIsBlock = kIsPlain<T> || IsFixedEigen<T>::value;
// Records are copied whole, padding and all: both ends share the layout.
template <>
constexpr bool kIsBlock<CallbackRecord> = true;
template <>
constexpr bool kIsBlock<TopicEvent> = true;

template <typename IO, typename T>
requires kIsBlock<T>
bool Io(IO& io, T& v) { return io.Bytes(&v, sizeof v); }
template <typename IO>
bool Io(IO& io, std::string& s) {
  size_t n = s.size();
  if (!io.Count(n, 1)) return false;
  s.resize(n);
  return io.Bytes(s.data(), n);
}
// Each message type's fields, declared before the vector template that
// walks their elements.
template <typename IO>
bool Io(IO& io, Header& m);
template <typename IO>
bool Io(IO& io, geometry::Pose2& m);
template <typename IO>
bool Io(IO& io, geometry::Path2& m);
template <typename IO>
bool Io(IO& io, TrackedObject& m);
template <typename IO>
bool Io(IO& io, TrajectoryPoint& m);
template <typename IO>
bool Io(IO& io, StopReasonMsg& m);
template <typename IO>
bool Io(IO& io, ParkingPathPoint& m);

template <typename IO, typename T>
bool Io(IO& io, std::vector<T>& v) {
  size_t n = v.size();
  if (!io.Count(n, kIsBlock<T> ? sizeof(T) : 1)) return false;
  v.resize(n);
  if constexpr (kIsBlock<T>) {
    return io.Bytes(v.data(), n * sizeof(T));
  } else {
    for (T& e : v)
      if (!Io(io, e)) return false;
    return true;
  }
}
template <typename IO, typename... Fields>
bool All(IO& io, Fields&... fields) {
  return (Io(io, fields) && ...);
}

template <typename IO>
bool Io(IO& io, Header& m) {
  return All(io, m.stamp_s, m.perception_stamp_s);
}
template <typename IO>
bool Io(IO& io, geometry::Pose2& m) {
  return All(io, m.x_m, m.y_m, m.yaw_rad);
}
template <typename IO>
bool Io(IO& io, geometry::Path2& m) {
  return All(io, m.points, m.s_m);
}
template <typename IO>
bool Io(IO& io, TrackedObject& m) {
  return All(io, m.id, m.position, m.velocity, m.length_m, m.width_m, m.yaw_rad,
             m.age);
}
template <typename IO>
bool Io(IO& io, TrajectoryPoint& m) {
  return All(io, m.x_m, m.y_m, m.yaw_rad, m.s_m, m.v_mps, m.curvature_1pm);
}
template <typename IO>
bool Io(IO& io, StopReasonMsg& m) {
  return All(io, m.header, m.reason, m.stop_distance_m, m.track_id,
             m.obstacle_gap_m, m.static_structure);
}
template <typename IO>
bool Io(IO& io, ParkingPathPoint& m) {
  return All(io, m.x_m, m.y_m, m.yaw_rad, m.reverse);
}
template <typename IO>
bool Io(IO& io, PointCloudMsg& m) {
  return All(io, m.header, m.points);
}
template <typename IO>
bool Io(IO& io, OdometryMsg& m) {
  return All(io, m.header, m.v_mps, m.yaw_rate_rps);
}
template <typename IO>
bool Io(IO& io, PoseMsg& m) {
  return All(io, m.header, m.time_s, m.pose, m.covariance, m.v_mps, m.fitness,
             m.valid);
}
template <typename IO>
bool Io(IO& io, ObjectsMsg& m) {
  return All(io, m.header, m.objects);
}
template <typename IO>
bool Io(IO& io, TrafficSignalMsg& m) {
  return All(io, m.header, m.state, m.stop_line_distance_m, m.tls_id);
}
template <typename IO>
bool Io(IO& io, PathMsg& m) {
  return All(io, m.header, m.path);
}
template <typename IO>
bool Io(IO& io, TrajectoryMsg& m) {
  return All(io, m.header, m.points, m.ends_at_goal, m.localization_lost,
             m.ego_v_mps, m.ego_pose, m.signal_stop, m.signal_stop_s_m, m.stop,
             m.route_leg);
}
template <typename IO>
bool Io(IO& io, ParkingPathMsg& m) {
  return All(io, m.header, m.found, m.hold, m.poses, m.failure, m.expansions);
}
template <typename IO>
bool Io(IO& io, ParkingDoneMsg& m) {
  return All(io, m.header, m.turnaround);
}
template <typename IO>
bool Io(IO& io, ControlMsg& m) {
  return All(io, m.header, m.accel_mps2, m.steer_rad, m.reverse);
}

template <typename IO>
bool Io(IO& io, Trace& m) {
  return All(io, m.callbacks, m.topic_events, m.timer_overruns);
}

struct Codec {
  std::function<void(const void*, std::string*)> encode;
  std::function<Result<MessagePtr>(std::string_view)> decode;
};

template <typename T>
Result<T> DecodeAs(std::string_view bytes, const char* what) {
  T value;
  Reader reader(bytes);
  if (!Io(reader, value)) {
    return Status::Corruption(fmt::format(
        "{} cut short: {} bytes do not hold it", what, bytes.size()));
  }
  if (reader.left() != 0) {
    return Status::Corruption(
        fmt::format("{}: {} bytes left over", what, reader.left()));
  }
  return value;
}

template <typename T>
std::pair<std::type_index, Codec> Entry() {
  Codec codec;
  codec.encode = [](const void* message, std::string* out) {
    Writer writer(out);
    // The writer only reads the fields the shared field list names.
    Io(writer, *const_cast<T*>(static_cast<const T*>(message)));
  };
  codec.decode = [](std::string_view bytes) -> Result<MessagePtr> {
    Result<T> value = DecodeAs<T>(bytes, typeid(T).name());
    if (!value.ok()) return value.status();
    return MessagePtr(std::make_shared<const T>(std::move(value).value()));
  };
  return {std::type_index(typeid(T)), std::move(codec)};
}

const std::map<std::type_index, Codec>& Codecs() {
  static const auto* const kCodecs = new std::map<std::type_index, Codec>{
      Entry<PointCloudMsg>(),    Entry<OdometryMsg>(),
      Entry<PoseMsg>(),          Entry<ObjectsMsg>(),
      Entry<TrafficSignalMsg>(), Entry<PathMsg>(),
      Entry<StopReasonMsg>(),    Entry<TrajectoryMsg>(),
      Entry<ParkingPathMsg>(),   Entry<ParkingDoneMsg>(),
      Entry<ControlMsg>()};
  return *kCodecs;
}

Result<const Codec*> Find(std::type_index type) {
  auto it = Codecs().find(type);
  if (it == Codecs().end()) {
    return Status::InvalidArgument(
        fmt::format("no codec for message type {}", type.name()));
  }
  return &it->second;
}

}  // namespace

bool CanEncodeMessage(std::type_index type) { return Codecs().count(type) > 0; }

Status EncodeMessage(std::type_index type, const MessagePtr& message,
                     std::string* out) {
  Result<const Codec*> codec = Find(type);
  if (!codec.ok()) return codec.status();
  if (message == nullptr)
    return Status::InvalidArgument("a null message cannot be encoded");
  (*codec)->encode(message.get(), out);
  return Status::Ok();
}

Result<MessagePtr> DecodeMessage(std::type_index type, std::string_view bytes) {
  Result<const Codec*> codec = Find(type);
  if (!codec.ok()) return codec.status();
  return (*codec)->decode(bytes);
}

void EncodeTrace(const Trace& trace, std::string* out) {
  Writer writer(out);
  Io(writer, const_cast<Trace&>(trace));
}

Result<Trace> DecodeTrace(std::string_view bytes) {
  return DecodeAs<Trace>(bytes, "trace");
}

}  // namespace adse::stack
