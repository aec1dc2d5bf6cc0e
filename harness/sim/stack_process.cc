#include "harness/sim/stack_process.h"

#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "stack/runtime/message_codec.h"

namespace adse::sim {
namespace {

// Frames both ways: a fixed header, then `length` bytes of payload.
enum FrameKind : uint32_t {
  // To the stack: index = topic, a = stamp, b = publish time; payload the
  // message.
  kPublish = 1,
  // To the stack: a = the time to advance to.
  kAdvance = 2,
  // To the stack: stop and send the trace.
  kStop = 3,
  // From the stack: the executor made (index = status code, payload its
  // message).
  kReady = 10,
  // From the stack: index = sink, a = its time; payload the message.
  kSink = 11,
  // From the stack: AdvanceTo returned (index = status code, a = now,
  // payload the status message).
  kAdvanced = 12,
  // From the stack: payload the trace.
  kTrace = 13,
  // From the stack: payload the frames of one step (its sinks' kSink, then
  // kAdvanced), sent as one write.
  kStep = 14,
};

struct FrameHeader {
  uint32_t kind = 0;
  int32_t index = 0;
  double a_s = 0.0;
  double b_s = 0.0;
  uint64_t length = 0;
};

// How long the stack's process may stay silent while an answer is due.
constexpr int kSilenceLimitMs = 60000;

Status StatusFrom(int32_t code, std::string message) {
  switch (static_cast<Status::Code>(code)) {
    case Status::Code::kOk:
      return Status::Ok();
    case Status::Code::kInvalidArgument:
      return Status::InvalidArgument(std::move(message));
    case Status::Code::kNotFound:
      return Status::NotFound(std::move(message));
    case Status::Code::kCorruption:
      return Status::Corruption(std::move(message));
    case Status::Code::kIoError:
      return Status::IoError(std::move(message));
    case Status::Code::kUnavailable:
      return Status::Unavailable(std::move(message));
    case Status::Code::kInternal:
      break;
  }
  return Status::Internal(std::move(message));
}

// Appends a frame to `out`: the frames of one step leave as one write.
void AppendFrame(const FrameHeader& header, std::string_view payload,
                 std::string* out) {
  out->append(reinterpret_cast<const char*>(&header), sizeof header);
  out->append(payload);
}

// Writes all of header and payload; false when the other end is gone.
bool WriteFrame(int fd, const FrameHeader& header, const std::string& payload) {
  std::vector<iovec> parts = {
      {const_cast<FrameHeader*>(&header), sizeof header},
      {const_cast<char*>(payload.data()), payload.size()}};
  size_t part = 0;
  while (part < parts.size()) {
    msghdr msg{};
    msg.msg_iov = parts.data() + part;
    msg.msg_iovlen = parts.size() - part;
    const ssize_t n = ::sendmsg(fd, &msg, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    size_t left = static_cast<size_t>(n);
    while (part < parts.size() && left >= parts[part].iov_len) {
      left -= parts[part].iov_len;
      ++part;
    }
    if (part < parts.size()) {
      parts[part].iov_base = static_cast<char*>(parts[part].iov_base) + left;
      parts[part].iov_len -= left;
    }
  }
  return true;
}

// Reads exactly n bytes; 0 on end of stream, -1 on error, n on success.
ssize_t ReadFull(int fd, void* data, size_t n) {
  size_t got = 0;
  while (got < n) {
    const ssize_t r = ::read(fd, static_cast<char*>(data) + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return r;
    got += static_cast<size_t>(r);
  }
  return static_cast<ssize_t>(got);
}

bool ReadFrame(int fd, FrameHeader* header, std::string* payload) {
  if (ReadFull(fd, header, sizeof *header) != sizeof *header) return false;
  payload->resize(header->length);
  return header->length == 0 || ReadFull(fd, payload->data(), header->length) ==
                                    static_cast<ssize_t>(header->length);
}

// ---- The stack's process --------------------------------------------------

// Runs in the forked child: makes the executor, then serves frames until
// told to stop or the world's end of the socket closes. Never returns.
[[noreturn]] void ServeStack(int fd, const stack::Graph& world_graph,
                             const MakeStackExecutor& make) {
  // The world's process handles Ctrl-C and SIGTERM and ends this one by
  // closing the socket; with the world gone this one dies too.
  ::signal(SIGINT, SIG_IGN);
  ::signal(SIGTERM, SIG_IGN);
  ::signal(SIGPIPE, SIG_IGN);

  // The graph as the world built it, but its sinks send what they take
  // back to the world, in order, with their times.
  std::string outgoing;
  stack::Graph graph = world_graph;
  for (size_t i = 0; i < graph.sinks().size(); ++i) {
    const std::type_index type = graph.topics()[graph.sinks()[i].topic].type;
    graph.RebindSink(i, [i, type, &outgoing](const stack::MessagePtr& m,
                                             double t_s) {
      std::string payload;
      (void)stack::EncodeMessage(type, m, &payload);  // checked at Start
      AppendFrame({kSink, static_cast<int32_t>(i), t_s, 0.0, payload.size()},
                  payload, &outgoing);
    });
  }

  Result<std::unique_ptr<stack::Executor>> made = make(&graph);
  {
    const Status& s = made.status();
    if (!WriteFrame(
            fd,
            {kReady, static_cast<int32_t>(s.code()), 0, 0, s.message().size()},
            s.message()) ||
        !made.ok()) {
      ::_exit(made.ok() ? 2 : 1);
    }
  }
  stack::Executor& executor = **made;
  FrameHeader in;
  std::string payload;
  while (ReadFrame(fd, &in, &payload)) {
    if (in.kind == kPublish) {
      const int topic = in.index;
      Result<stack::MessagePtr> message =
          stack::DecodeMessage(graph.topics()[topic].type, payload);
      if (!message.ok()) break;  // cannot happen between one binary's ends
      executor.PublishExternal(topic, *message, in.a_s, in.b_s);
    } else if (in.kind == kAdvance) {
      const Status s = executor.AdvanceTo(in.a_s);
      AppendFrame({kAdvanced, static_cast<int32_t>(s.code()), executor.now_s(),
                   0.0, s.message().size()},
                  s.message(), &outgoing);
      const bool sent =
          WriteFrame(fd, {kStep, 0, 0, 0, outgoing.size()}, outgoing);
      outgoing.clear();
      if (!sent) break;
    } else if (in.kind == kStop) {
      executor.Stop();
      std::string trace;
      stack::EncodeTrace(executor.trace(), &trace);
      WriteFrame(fd, {kTrace, 0, 0, 0, trace.size()}, trace);
      ::_exit(0);
    } else {
      break;
    }
  }
  executor.Stop();
  ::_exit(0);
}

}  // namespace

Result<std::unique_ptr<StackProcess>> StackProcess::Start(
    const stack::Graph* graph, MakeStackExecutor make) {
  for (const stack::SinkSpec& sink : graph->sinks()) {
    const stack::TopicSpec& topic = graph->topics().at(sink.topic);
    if (!stack::CanEncodeMessage(topic.type)) {
      return Status::InvalidArgument(fmt::format(
          "topic {} has a sink but its messages cannot cross to another "
          "process (no codec for {})",
          topic.name, topic.type.name()));
    }
  }
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) {
    return Status::IoError(fmt::format("the stack's process: socketpair: {}",
                                       std::strerror(errno)));
  }
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    return Status::IoError(
        fmt::format("the stack's process: fork: {}", std::strerror(error)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(1);
    ServeStack(fds[1], *graph, make);
  }
  ::close(fds[1]);
  std::unique_ptr<StackProcess> process(new StackProcess());
  process->graph_ = graph;
  process->pid_ = pid;
  process->alive_ = true;
  process->fd_ = fds[0];
  Status received = process->Receive();
  if (!received.ok()) return received;
  if (process->in_kind_ != kReady) {
    return process->Ended("it sent something else than its first word", true);
  }
  Status made = StatusFrom(process->in_index_, process->in_payload_);
  if (!made.ok()) {
    (void)process->Ended("", false);
    return made;
  }
  return process;
}

StackProcess::~StackProcess() {
  if (fd_ >= 0) ::close(fd_);
  if (!alive_) return;
  // Closing the socket ends it; give it 5 s to stop its threads.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(5);
  int wstatus = 0;
  while (::waitpid(pid_, &wstatus, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, &wstatus, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

Status StackProcess::Send(uint32_t kind, int32_t index, double a_s, double b_s,
                          const std::string& payload) {
  if (!alive_) return Status::Internal("the stack's process has ended");
  if (!WriteFrame(fd_, {kind, index, a_s, b_s, payload.size()}, payload))
    return Ended("sending to it failed", false);
  if (kind == kPublish) ++messages_out_;
  bytes_out_ += static_cast<int64_t>(sizeof(FrameHeader) + payload.size());
  return Status::Ok();
}

Status StackProcess::Receive() {
  pollfd p{fd_, POLLIN, 0};
  int ready = 0;
  do {
    ready = ::poll(&p, 1, kSilenceLimitMs);
  } while (ready < 0 && errno == EINTR);
  if (ready == 0) {
    return Ended(
        fmt::format("it said nothing for {} s", kSilenceLimitMs / 1000), true);
  }
  FrameHeader header;
  if (ready < 0 || !ReadFrame(fd_, &header, &in_payload_))
    return Ended("its socket closed", false);
  in_kind_ = header.kind;
  in_index_ = header.index;
  bytes_in_ += static_cast<int64_t>(sizeof header + header.length);
  return Status::Ok();
}

Status StackProcess::Ended(const std::string& what, bool kill) {
  if (!alive_) return Status::Internal("the stack's process has ended");
  if (kill) ::kill(pid_, SIGKILL);
  int wstatus = 0;
  pid_t reaped = 0;
  do {
    reaped = ::waitpid(pid_, &wstatus, 0);
  } while (reaped < 0 && errno == EINTR);
  const pid_t pid = pid_;
  alive_ = false;
  std::string how = "it is gone";
  if (reaped == pid && WIFSIGNALED(wstatus)) {
    how = fmt::format("it was killed by signal {} ({})", WTERMSIG(wstatus),
                      ::strsignal(WTERMSIG(wstatus)));
  } else if (reaped == pid && WIFEXITED(wstatus)) {
    how = fmt::format("it exited with status {}", WEXITSTATUS(wstatus));
  }
  return Status::Internal(fmt::format("the stack's process {}: {}{}{}", pid,
                                      what, what.empty() ? "" : "; ", how));
}

void StackProcess::PublishExternal(int topic, stack::MessagePtr message,
                                   double stamp_s, double t_s) {
  if (!send_status_.ok()) return;
  std::string payload;
  const stack::TopicSpec& spec = graph_->topics().at(topic);
  send_status_ = stack::EncodeMessage(spec.type, message, &payload);
  if (!send_status_.ok()) {
    send_status_ = send_status_.WithContext("publishing on " + spec.name);
    return;
  }
  send_status_ = Send(kPublish, topic, stamp_s, t_s, payload);
}

Status StackProcess::AdvanceTo(double t_s) {
  if (!send_status_.ok()) return send_status_;
  Status sent = Send(kAdvance, 0, t_s, 0.0, std::string());
  if (!sent.ok()) return sent;
  // The answer comes as one write: the frame that carries the sinks'
  // frames, and the kAdvanced frame inside it.
  Status received = Receive();
  if (!received.ok()) return received;
  if (in_kind_ != kStep)
    return Ended("it answered a step with something else", true);
  std::string_view frames = in_payload_;
  while (frames.size() >= sizeof(FrameHeader)) {
    FrameHeader h;
    std::memcpy(&h, frames.data(), sizeof h);
    frames.remove_prefix(sizeof h);
    if (frames.size() < h.length) break;
    const std::string_view payload = frames.substr(0, h.length);
    frames.remove_prefix(h.length);
    if (h.kind == kSink) {
      const stack::SinkSpec& sink = graph_->sinks().at(h.index);
      Result<stack::MessagePtr> message =
          stack::DecodeMessage(graph_->topics()[sink.topic].type, payload);
      if (!message.ok()) return message.status().WithContext("from the stack");
      ++messages_in_;
      sink.fn(*message, h.a_s);
    } else if (h.kind == kAdvanced) {
      now_s_ = h.a_s;
      return StatusFrom(h.index, std::string(payload));
    }
  }
  return Ended("its answer to a step was cut short", true);
}

void StackProcess::Stop() {
  if (stopped_) return;
  stopped_ = true;
  stop_status_ = Send(kStop, 0, 0.0, 0.0, std::string());
  if (stop_status_.ok()) stop_status_ = Receive();
  if (stop_status_.ok() && in_kind_ != kTrace)
    stop_status_ = Ended("it answered Stop with no trace", true);
  if (!stop_status_.ok()) return;
  Result<stack::Trace> trace = stack::DecodeTrace(in_payload_);
  if (!trace.ok()) {
    stop_status_ = trace.status().WithContext("the stack's trace");
    return;
  }
  trace_ = std::move(trace).value();
}

std::string StackProcess::Describe() const {
  return fmt::format(
      "process {}, {} messages ({:.1f} MB) to it and {} ({:.1f} MB) back "
      "over a Unix socket",
      pid_, messages_out_, bytes_out_ / 1e6, messages_in_, bytes_in_ / 1e6);
}

}  // namespace adse::sim
