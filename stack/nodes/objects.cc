#include "stack/nodes/objects.h"

namespace adse::stack {

TrackedObject ObjectFromDetection(const algorithms::Detection& detection) {
  TrackedObject o;
  o.position = detection.center;
  o.length_m = detection.length_m;
  o.width_m = detection.width_m;
  o.yaw_rad = detection.yaw_rad;
  return o;
}

algorithms::Detection DetectionFromObject(const TrackedObject& object) {
  algorithms::Detection d;
  d.center = object.position;
  d.length_m = object.length_m;
  d.width_m = object.width_m;
  d.yaw_rad = object.yaw_rad;
  return d;
}

TrackedObject ObjectFromTrack(const algorithms::Track& track) {
  TrackedObject o;
  o.id = track.id;
  o.position = track.position;
  o.velocity = track.velocity;
  o.length_m = track.length_m;
  o.width_m = track.width_m;
  o.yaw_rad = track.yaw_rad;
  o.age = track.age;
  return o;
}

algorithms::PlannerObstacle ObstacleFromObject(const TrackedObject& object) {
  algorithms::PlannerObstacle ob;
  ob.id = object.id;
  ob.position = object.position;
  ob.velocity = object.velocity;
  ob.length_m = object.length_m;
  ob.width_m = object.width_m;
  ob.yaw_rad = object.yaw_rad;
  ob.age = object.age;
  return ob;
}

}  // namespace adse::stack
