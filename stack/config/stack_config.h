// The stack's tunable parameters ("knobs"), addressable by path such as
// `lidar.rate_hz`, so that the scenario's `stack:` section and the design
// space can set any of them. Each node's typed parameter struct is filled
// from here.
#ifndef ADSE_STACK_CONFIG_STACK_CONFIG_H_
#define ADSE_STACK_CONFIG_STACK_CONFIG_H_

#include <map>
#include <string>
#include <vector>

#include "stack/base/status.h"
#include "stack/world/lidar.h"
#include "stack/world/traffic_signal_detector.h"

namespace adse {

struct KnobInfo {
  std::string path;      // "lidar.rate_hz" (without the `stack.` prefix)
  bool integer = false;  // only whole numbers allowed
  double min_value = 0.0;
  double max_value = 0.0;
  double default_value = 0.0;
  std::string doc;  // one line, with the unit
  // What the knob does to the stack's work (a design space's default
  // `role`): kSensorRate, a sensor's publishing rate, whose lowering sheds
  // load from the whole chain behind the sensor; kDownsample, a step or
  // cell size that hands the stack fewer points, less work for less
  // precision.
  enum class Load { kOther, kSensorRate, kDownsample };
  Load load = Load::kOther;
};

// Every knob the stack has, in a stable order.
const std::vector<KnobInfo>& StackKnobs();
// The knob at `path`, or nullptr.
const KnobInfo* FindStackKnob(const std::string& path);

class StackConfig {
 public:
  // Sets a knob; InvalidArgument names the knob and its allowed range.
  Status Set(const std::string& path, double value);
  // The value set, or the knob's default. `path` must name a knob.
  double Get(const std::string& path) const;
  // Knobs that differ from their defaults.
  const std::map<std::string, double>& overrides() const { return values_; }

  world::LidarParams Lidar() const;
  world::TrafficSignalDetectorParams SignalDetector() const;

 private:
  std::map<std::string, double> values_;
};

}  // namespace adse

#endif  // ADSE_STACK_CONFIG_STACK_CONFIG_H_
