// A small ROS-2-like node graph: nodes, named typed topics, subscriptions
// with keep-last-N queues, and timers. The graph only describes; an
// Executor (executor.h) decides when callbacks run and what they cost.
#ifndef ADSE_STACK_RUNTIME_GRAPH_H_
#define ADSE_STACK_RUNTIME_GRAPH_H_

#include <functional>
#include <memory>
#include <string>
#include <typeindex>
#include <vector>

#include "stack/base/status.h"
#include "stack/runtime/cost_profile.h"
#include "stack/runtime/messages.h"

namespace adse::stack {

// Type-erased message; always a std::shared_ptr<const T> underneath.
using MessagePtr = std::shared_ptr<const void>;

class CallbackContext;

// What a callback reports about its own work, for the `counted` cost model
// and for data-parallel callbacks.
struct WorkReport {
  double units = 0.0;              // node-defined units (points in, iterations)
  double parallel_fraction = 0.0;  // Amdahl fraction that more cores speed up
  int max_threads = 1;             // cores the parallel part can use at most
};

struct TopicSpec {
  std::string name;
  std::type_index type = typeid(void);
};

struct NodeSpec {
  std::string name;
};

struct CallbackSpec {
  enum class Kind { kSubscription, kTimer };
  Kind kind = Kind::kSubscription;
  int node = -1;
  std::string name;       // "<node>/<callback>" unique in the graph
  int topic = -1;         // subscriptions: the topic taken from
  int queue_depth = 1;    // subscriptions: keep-last depth
  double period_s = 0.0;  // timers
  double phase_s = 0.0;   // timers: first fire time
  std::function<void(const MessagePtr&, CallbackContext&)> on_message;
  std::function<void(CallbackContext&)> on_timer;
};

// Subscribers outside the computer under test (the vehicle's actuators, the
// recorder): called at publish time, cost nothing, never queue.
struct SinkSpec {
  int topic = -1;
  std::function<void(const MessagePtr&, double t_s)> fn;
};

class Graph {
 public:
  template <typename T>
  int AddTopic(const std::string& name) {
    topics_.push_back({name, typeid(T)});
    return static_cast<int>(topics_.size()) - 1;
  }
  int AddNode(const std::string& name) {
    nodes_.push_back({name});
    return static_cast<int>(nodes_.size()) - 1;
  }
  // `fn(const T&, CallbackContext&)` runs for each message taken.
  template <typename T, typename Fn>
  int Subscribe(int node, int topic, const std::string& name, int queue_depth,
                Fn fn) {
    CallbackSpec spec;
    spec.kind = CallbackSpec::Kind::kSubscription;
    spec.node = node;
    spec.name = nodes_.at(node).name + "/" + name;
    spec.topic = topic;
    spec.queue_depth = queue_depth;
    spec.on_message = [fn](const MessagePtr& m, CallbackContext& ctx) {
      fn(*static_cast<const T*>(m.get()), ctx);
    };
    callbacks_.push_back(std::move(spec));
    return static_cast<int>(callbacks_.size()) - 1;
  }
  int AddTimer(int node, const std::string& name, double period_s,
               std::function<void(CallbackContext&)> fn, double phase_s = 0.0) {
    CallbackSpec spec;
    spec.kind = CallbackSpec::Kind::kTimer;
    spec.node = node;
    spec.name = nodes_.at(node).name + "/" + name;
    spec.period_s = period_s;
    spec.phase_s = phase_s;
    spec.on_timer = std::move(fn);
    callbacks_.push_back(std::move(spec));
    return static_cast<int>(callbacks_.size()) - 1;
  }
  template <typename T, typename Fn>
  void AddSink(int topic, Fn fn) {
    sinks_.push_back({topic, [fn](const MessagePtr& m, double t_s) {
                        fn(*static_cast<const T*>(m.get()), t_s);
                      }});
  }

  // Gives sink `index` another function, e.g. one that carries its
  // messages to the process where the first one runs.
  void RebindSink(size_t index,
                  std::function<void(const MessagePtr&, double t_s)> fn) {
    sinks_.at(index).fn = std::move(fn);
  }

  const std::vector<TopicSpec>& topics() const { return topics_; }
  const std::vector<NodeSpec>& nodes() const { return nodes_; }
  const std::vector<CallbackSpec>& callbacks() const { return callbacks_; }
  const std::vector<SinkSpec>& sinks() const { return sinks_; }
  // Index of the topic/node/callback with that name, or -1.
  int FindTopic(const std::string& name) const;
  int FindNode(const std::string& name) const;
  int FindCallback(const std::string& name) const;

 private:
  std::vector<TopicSpec> topics_;
  std::vector<NodeSpec> nodes_;
  std::vector<CallbackSpec> callbacks_;
  std::vector<SinkSpec> sinks_;
};

// Handed to a running callback: the simulated time and a way to publish.
// Publications are held and released when the callback completes (at
// start + cost on a virtual platform).
class CallbackContext {
 public:
  virtual ~CallbackContext() = default;
  // Simulated time at which this callback started.
  virtual double now_s() const = 0;
  // Every message type has a `header`; its stamp is traced for latency.
  template <typename T>
  void Publish(int topic, T message) {
    const double stamp_s = message.header.stamp_s;
    PublishErased(topic, std::make_shared<const T>(std::move(message)),
                  stamp_s);
  }
  // Reports the work done, for cost models (optional; default no units,
  // fully serial).
  virtual void ReportWork(const WorkReport& work) = 0;

 protected:
  virtual void PublishErased(int topic, MessagePtr message, double stamp_s) = 0;
};

// InvalidArgument naming the callback or sink: a node or topic index out
// of range, a queue_depth < 1, a timer period <= 0 or phase < 0, or a
// missing function. Every executor checks its graph with it.
Status ValidateGraph(const Graph& graph);

// InvalidArgument listing the graph's callbacks that `profile` has no
// entry for (they would cost nothing).
Status CheckProfileCovers(const CostProfile& profile, const Graph& graph);

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_GRAPH_H_
