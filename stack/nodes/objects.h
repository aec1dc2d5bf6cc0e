// The perception object message and the algorithm types the nodes turn it
// into and out of: clustering's detections, the tracker's tracks and the
// obstacle planner's obstacles. Each conversion keeps the box whole
// (centre, extents and heading).
#ifndef ADSE_STACK_NODES_OBJECTS_H_
#define ADSE_STACK_NODES_OBJECTS_H_

#include "stack/algorithms/clustering.h"
#include "stack/algorithms/planning.h"
#include "stack/algorithms/tracker.h"
#include "stack/runtime/messages.h"

namespace adse::stack {

// A detection already in the map frame (id 0: detections have none).
TrackedObject ObjectFromDetection(const algorithms::Detection& detection);
algorithms::Detection DetectionFromObject(const TrackedObject& object);
TrackedObject ObjectFromTrack(const algorithms::Track& track);
algorithms::PlannerObstacle ObstacleFromObject(const TrackedObject& object);

}  // namespace adse::stack

#endif  // ADSE_STACK_NODES_OBJECTS_H_
