// The virtual platform's refusals and errors: invalid options and graphs
// name the field, exceptions in callbacks and sinks name where they came
// from, and publications it cannot place are errors.
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "stack/runtime/executor.h"
#include "stack/runtime/graph.h"
#include "stack/runtime/trace.h"
#include "tests/stack/runtime/executor_test_util.h"

namespace adse::stack {
namespace {

using test::Counted;
using test::CreateVirtual;
using test::EventsOf;
using test::Msg;
using test::Noop;
using test::Publish;

std::string OptionsError(VirtualPlatformOptions o) {
  const Status s = ValidateVirtualPlatformOptions(o);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  Graph g;
  EXPECT_FALSE(CreateVirtualExecutor(&g, o).ok());
  return s.message();
}

TEST(VirtualExecutorTest, InvalidOptionsNameTheField) {
  EXPECT_TRUE(ValidateVirtualPlatformOptions({}).ok());
  VirtualPlatformOptions o;
  o.cores = 0;
  EXPECT_NE(OptionsError(o).find("cores"), std::string::npos);
  o = {};
  o.dispatch = static_cast<DispatchKind>(7);
  EXPECT_NE(OptionsError(o).find("dispatch"), std::string::npos);
  o = {};
  o.freq_ghz = -1.0;
  EXPECT_NE(OptionsError(o).find("freq_ghz"), std::string::npos);
  o = {};
  o.reference_ghz = 0.0;
  EXPECT_NE(OptionsError(o).find("reference_ghz"), std::string::npos);
  o = {};
  o.cost_scale = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(OptionsError(o).find("cost_scale"), std::string::npos);
  o = {};
  o.counted["n/cb"] = {-1.0, 0.0};
  EXPECT_NE(OptionsError(o).find("counted[n/cb].fixed_s"), std::string::npos);
  o = {};
  o.default_counted.per_unit_s = std::numeric_limits<double>::infinity();
  EXPECT_NE(OptionsError(o).find("default_counted.per_unit_s"),
            std::string::npos);
}

TEST(VirtualExecutorTest, InvalidGraphRejected) {
  {
    Graph g;
    g.AddTimer(g.AddNode("n"), "t", 0.0, [](CallbackContext&) {});
    auto r = CreateVirtualExecutor(&g, {});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("n/t"), std::string::npos);
    EXPECT_NE(r.status().message().find("period_s"), std::string::npos);
  }
  {
    Graph g;
    const int in = g.AddTopic<Msg>("in");
    g.Subscribe<Msg>(g.AddNode("n"), in, "cb", 0, Noop());
    auto r = CreateVirtualExecutor(&g, {});
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("queue_depth"), std::string::npos);
  }
  EXPECT_FALSE(CreateVirtualExecutor(nullptr, {}).ok());
}

TEST(VirtualExecutorTest, ExceptionInCallbackNamesIt) {
  Graph g;
  const int in = g.AddTopic<Msg>("in");
  g.Subscribe<Msg>(
      g.AddNode("planner"), in, "plan", 1,
      [](const Msg&, CallbackContext&) { throw std::runtime_error("boom"); });
  auto ex = CreateVirtual(g, Counted(1, {}));
  Publish(*ex, in, 0, 0.0);
  const Status s = ex->AdvanceTo(1.0);
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("planner/plan"), std::string::npos);
  EXPECT_NE(s.message().find("boom"), std::string::npos);
  EXPECT_EQ(ex->AdvanceTo(2.0).code(), Status::Code::kInternal);  // sticky
}

TEST(VirtualExecutorTest, NonStandardExceptionInTimer) {
  Graph g;
  g.AddTimer(g.AddNode("n"), "t", 1.0, [](CallbackContext&) { throw 42; });
  auto ex = CreateVirtual(g, Counted(1, {}));
  const Status s = ex->AdvanceTo(1.0);
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("n/t"), std::string::npos);
}

TEST(VirtualExecutorTest, ExceptionInSinkIsAnError) {
  Graph g;
  const int in = g.AddTopic<Msg>("in");
  g.AddSink<Msg>(
      in, [](const Msg&, double) { throw std::runtime_error("actuator"); });
  auto ex = CreateVirtual(g, Counted(1, {}));
  Publish(*ex, in, 0, 0.0);
  const Status s = ex->AdvanceTo(1.0);
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("in"), std::string::npos);
  EXPECT_NE(s.message().find("actuator"), std::string::npos);
}

TEST(VirtualExecutorTest, PublishToUnknownTopicNamesCallback) {
  Graph g;
  g.AddTimer(g.AddNode("n"), "t", 1.0,
             [](CallbackContext& ctx) { ctx.Publish(99, Msg{}); });
  auto ex = CreateVirtual(g, Counted(1, {}));
  const Status s = ex->AdvanceTo(1.0);
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("n/t"), std::string::npos);
}

TEST(VirtualExecutorTest, ExternalPublicationInThePastIsAnError) {
  Graph g;
  const int in = g.AddTopic<Msg>("in");
  auto ex = CreateVirtual(g, Counted(1, {}));
  ASSERT_TRUE(ex->AdvanceTo(1.0).ok());
  Publish(*ex, in, 0, 1.0 - 1e-12);  // rounding: moved to now
  ASSERT_TRUE(ex->AdvanceTo(1.5).ok());
  EXPECT_EQ(EventsOf(ex->trace(), TopicEvent::kPublish, in).size(), 1u);
  EXPECT_DOUBLE_EQ(ex->trace().topic_events[0].t_s, 1.0);
  Publish(*ex, in, 1, 0.5);
  EXPECT_EQ(ex->AdvanceTo(2.0).code(), Status::Code::kInvalidArgument);
}

TEST(VirtualExecutorTest, UnknownExternalTopicIsAnError) {
  Graph g;
  g.AddTopic<Msg>("in");
  auto ex = CreateVirtual(g, Counted(1, {}));
  ex->PublishExternal(3, std::make_shared<const Msg>(), 0.0, 0.0);
  EXPECT_EQ(ex->AdvanceTo(1.0).code(), Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace adse::stack
