// Messages cross between the world's and the stack's processes as bytes:
// every message type comes back field for field, and broken bytes are
// refused, never read past.
#include "stack/runtime/message_codec.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "stack/runtime/messages.h"

namespace adse::stack {
namespace {

template <typename T>
T RoundTrip(const T& message) {
  std::string bytes;
  Status encoded =
      EncodeMessage(typeid(T), std::make_shared<const T>(message), &bytes);
  EXPECT_TRUE(encoded.ok()) << encoded.ToString();
  Result<MessagePtr> decoded = DecodeMessage(typeid(T), bytes);
  EXPECT_TRUE(decoded.ok()) << decoded.status().ToString();
  if (!decoded.ok()) return T{};
  return *static_cast<const T*>(decoded->get());
}

TEST(MessageCodecTest, EveryMessageTypeOfTheStackComesBackFieldForField) {
  PointCloudMsg cloud;
  cloud.header.stamp_s = 1.25;
  cloud.points = {{1.f, 2.f, 3.f}, {-4.5f, 0.f, 7.f}};
  const PointCloudMsg cloud2 = RoundTrip(cloud);
  EXPECT_EQ(cloud2.header.stamp_s, 1.25);
  ASSERT_EQ(cloud2.points.size(), 2u);
  EXPECT_EQ(cloud2.points[1], cloud.points[1]);

  PoseMsg pose;
  pose.time_s = 12.5;
  pose.pose = {3.0, -2.0, 0.5};
  pose.covariance(1, 2) = 0.25;
  pose.v_mps = 7.5;
  pose.fitness = 0.125;
  pose.valid = false;
  const PoseMsg pose2 = RoundTrip(pose);
  EXPECT_EQ(pose2.time_s, 12.5);
  EXPECT_EQ(pose2.pose.y_m, -2.0);
  EXPECT_EQ(pose2.covariance, pose.covariance);
  EXPECT_EQ(pose2.v_mps, 7.5);
  EXPECT_FALSE(pose2.valid);

  ObjectsMsg objects;
  objects.objects.resize(2);
  objects.objects[1].id = 42;
  objects.objects[1].velocity = {1.5, -0.5};
  objects.objects[1].yaw_rad = -1.25;
  objects.objects[1].age = 9;
  const ObjectsMsg objects2 = RoundTrip(objects);
  ASSERT_EQ(objects2.objects.size(), 2u);
  EXPECT_EQ(objects2.objects[1].id, 42);
  EXPECT_EQ(objects2.objects[1].velocity, objects.objects[1].velocity);
  EXPECT_EQ(objects2.objects[1].yaw_rad, -1.25);
  EXPECT_EQ(objects2.objects[1].age, 9);

  TrafficSignalMsg signal;
  signal.state = SignalState::kYellow;
  signal.stop_line_distance_m = 31.5;
  signal.tls_id = "cluster_1_2";
  const TrafficSignalMsg signal2 = RoundTrip(signal);
  EXPECT_EQ(signal2.state, SignalState::kYellow);
  EXPECT_EQ(signal2.stop_line_distance_m, 31.5);
  EXPECT_EQ(signal2.tls_id, "cluster_1_2");

  PathMsg path;
  path.path.points = {{0.0, 0.0}, {3.0, 4.0}};
  path.path.s_m = {0.0, 5.0};
  const PathMsg path2 = RoundTrip(path);
  EXPECT_EQ(path2.path.points, path.path.points);
  EXPECT_EQ(path2.path.s_m, path.path.s_m);

  TrajectoryMsg trajectory;
  trajectory.points.resize(3);
  trajectory.points[2].v_mps = 4.25;
  trajectory.points[2].curvature_1pm = -0.125;
  trajectory.signal_stop = true;
  trajectory.signal_stop_s_m = 88.0;
  trajectory.stop.reason = StopReason::kObstacle;
  trajectory.stop.track_id = 7;
  trajectory.stop.static_structure = true;
  trajectory.route_leg = 2;
  trajectory.ego_pose = {1.5, -2.0, 0.25};
  const TrajectoryMsg trajectory2 = RoundTrip(trajectory);
  EXPECT_EQ(trajectory2.route_leg, 2);
  EXPECT_EQ(trajectory2.ego_pose.y_m, -2.0);
  EXPECT_EQ(trajectory2.ego_pose.yaw_rad, 0.25);
  ASSERT_EQ(trajectory2.points.size(), 3u);
  EXPECT_EQ(trajectory2.points[2].curvature_1pm, -0.125);
  EXPECT_TRUE(trajectory2.signal_stop);
  EXPECT_EQ(trajectory2.signal_stop_s_m, 88.0);
  EXPECT_EQ(trajectory2.stop.reason, StopReason::kObstacle);
  EXPECT_EQ(trajectory2.stop.track_id, 7);
  EXPECT_TRUE(trajectory2.stop.static_structure);

  StopReasonMsg stop;
  stop.reason = StopReason::kRedLight;
  stop.stop_distance_m = 12.5;
  stop.obstacle_gap_m = 3.0;
  const StopReasonMsg stop2 = RoundTrip(stop);
  EXPECT_EQ(stop2.reason, StopReason::kRedLight);
  EXPECT_EQ(stop2.stop_distance_m, 12.5);
  EXPECT_EQ(stop2.obstacle_gap_m, 3.0);

  ParkingPathMsg parking;
  parking.found = true;
  parking.hold = true;
  parking.poses = {{1.0, 2.0, 0.5, false}, {3.0, 4.0, 1.5, true}};
  parking.failure = "";
  parking.expansions = int64_t{1} << 40;
  const ParkingPathMsg parking2 = RoundTrip(parking);
  EXPECT_TRUE(parking2.hold);
  ASSERT_EQ(parking2.poses.size(), 2u);
  EXPECT_TRUE(parking2.poses[1].reverse);
  EXPECT_EQ(parking2.poses[1].yaw_rad, 1.5);
  EXPECT_EQ(parking2.expansions, int64_t{1} << 40);

  ControlMsg control;
  control.header.stamp_s = 9.5;
  control.accel_mps2 = -3.0;
  control.steer_rad = 0.25;
  control.reverse = true;
  const ControlMsg control2 = RoundTrip(control);
  EXPECT_EQ(control2.header.stamp_s, 9.5);
  EXPECT_EQ(control2.accel_mps2, -3.0);
  EXPECT_EQ(control2.steer_rad, 0.25);
  EXPECT_TRUE(control2.reverse);

  OdometryMsg odometry;
  odometry.v_mps = 5.5;
  odometry.yaw_rate_rps = -0.0625;
  EXPECT_EQ(RoundTrip(odometry).yaw_rate_rps, -0.0625);
  ParkingDoneMsg done;
  done.header.stamp_s = 3.0;
  done.turnaround = 1;
  EXPECT_EQ(RoundTrip(done).header.stamp_s, 3.0);
  EXPECT_EQ(RoundTrip(done).turnaround, 1);
}

TEST(MessageCodecTest, BytesCutShortOrLeftOverAreRefused) {
  TrafficSignalMsg signal;
  signal.tls_id = "gneJ1";
  std::string bytes;
  ASSERT_TRUE(EncodeMessage(typeid(TrafficSignalMsg),
                            std::make_shared<const TrafficSignalMsg>(signal),
                            &bytes)
                  .ok());
  for (size_t n = 0; n < bytes.size(); ++n) {
    Result<MessagePtr> cut =
        DecodeMessage(typeid(TrafficSignalMsg), bytes.substr(0, n));
    ASSERT_FALSE(cut.ok()) << n;
    EXPECT_EQ(cut.status().code(), Status::Code::kCorruption);
    EXPECT_NE(cut.status().message().find("cut short"), std::string::npos);
  }
  Result<MessagePtr> longer =
      DecodeMessage(typeid(TrafficSignalMsg), bytes + "x");
  ASSERT_FALSE(longer.ok());
  EXPECT_NE(longer.status().message().find("1 bytes left over"),
            std::string::npos)
      << longer.status().message();
}

TEST(MessageCodecTest, ACountTheBytesCannotHoldIsRefusedBeforeAllocating) {
  PointCloudMsg cloud;
  std::string bytes;
  ASSERT_TRUE(EncodeMessage(typeid(PointCloudMsg),
                            std::make_shared<const PointCloudMsg>(cloud),
                            &bytes)
                  .ok());
  // The header's two stamps, then the points' count: claim 2^60 points.
  const uint64_t huge = uint64_t{1} << 60;
  bytes.replace(sizeof(Header), sizeof huge,
                reinterpret_cast<const char*>(&huge), sizeof huge);
  Result<MessagePtr> decoded = DecodeMessage(typeid(PointCloudMsg), bytes);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), Status::Code::kCorruption);
}

TEST(MessageCodecTest, ATypeWithoutACodecIsNamedNotGuessed) {
  struct Unknown {
    Header header;
  };
  EXPECT_FALSE(CanEncodeMessage(typeid(Unknown)));
  EXPECT_TRUE(CanEncodeMessage(typeid(ControlMsg)));
  std::string bytes;
  Status s =
      EncodeMessage(typeid(Unknown), std::make_shared<const Unknown>(), &bytes);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("no codec"), std::string::npos);
  EXPECT_EQ(DecodeMessage(typeid(Unknown), "").status().code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(EncodeMessage(typeid(ControlMsg), nullptr, &bytes).code(),
            Status::Code::kInvalidArgument);
}

TEST(MessageCodecTest, ATraceComesBackRecordForRecord) {
  Trace trace;
  CallbackRecord r;
  r.callback = 3;
  r.start_s = 1.5;
  r.end_s = 1.75;
  r.work_units = 1234.0;
  r.first_core = 2;
  trace.callbacks = {r, r};
  trace.callbacks[1].callback = 4;
  TopicEvent e;
  e.kind = TopicEvent::kDrop;
  e.topic = 5;
  e.seq = 99;
  trace.topic_events = {e};
  trace.timer_overruns = {0, 2, 7};
  std::string bytes;
  EncodeTrace(trace, &bytes);
  Result<Trace> back = DecodeTrace(bytes);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->callbacks.size(), 2u);
  EXPECT_EQ(back->callbacks[1].callback, 4);
  EXPECT_EQ(back->callbacks[0].end_s, 1.75);
  EXPECT_EQ(back->callbacks[0].work_units, 1234.0);
  EXPECT_EQ(back->callbacks[0].first_core, 2);
  ASSERT_EQ(back->topic_events.size(), 1u);
  EXPECT_EQ(back->topic_events[0].kind, TopicEvent::kDrop);
  EXPECT_EQ(back->topic_events[0].seq, 99u);
  EXPECT_EQ(back->timer_overruns, trace.timer_overruns);
  EXPECT_FALSE(DecodeTrace(bytes.substr(0, bytes.size() - 1)).ok());
}

}  // namespace
}  // namespace adse::stack
