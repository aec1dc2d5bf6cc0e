// Messages and traces as bytes, for a stack that runs in another process
// than the world (platform.kind: cgroup). Both ends are the same binary on
// the same host, so numbers travel in the host's own layout: this is a
// channel between two processes, not a file or network format.
#ifndef ADSE_STACK_RUNTIME_MESSAGE_CODEC_H_
#define ADSE_STACK_RUNTIME_MESSAGE_CODEC_H_

#include <string>
#include <string_view>
#include <typeindex>

#include "stack/base/status.h"
#include "stack/runtime/graph.h"
#include "stack/runtime/trace.h"

namespace adse::stack {

// Whether messages of `type` (a topic's TopicSpec::type) can be encoded:
// every message type of messages.h can.
bool CanEncodeMessage(std::type_index type);

// Appends `message` (a std::shared_ptr<const T> underneath, T = `type`) to
// `out`. InvalidArgument for a type without a codec or a null message.
Status EncodeMessage(std::type_index type, const MessagePtr& message,
                     std::string* out);

// The message `bytes` encode. Corruption when they are cut short or have
// bytes left over; InvalidArgument for a type without a codec.
Result<MessagePtr> DecodeMessage(std::type_index type, std::string_view bytes);

// The same for a whole trace (plain records, copied as they are).
void EncodeTrace(const Trace& trace, std::string* out);
Result<Trace> DecodeTrace(std::string_view bytes);

}  // namespace adse::stack

#endif  // ADSE_STACK_RUNTIME_MESSAGE_CODEC_H_
