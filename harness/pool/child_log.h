// Reading what a worker child wrote to its log: shared by the local pool and
// the Slurm step pool.
#ifndef ADSE_HARNESS_POOL_CHILD_LOG_H_
#define ADSE_HARNESS_POOL_CHILD_LOG_H_

#include <cstddef>
#include <string>

namespace adse::pool {

// The last `max_bytes` of the file at `path`, starting at a line start where
// one lies inside them (a cut first line would read as a different message).
// Empty when the file cannot be read: a log tail is evidence, never a
// reason to fail.
std::string ReadLogTail(const std::string& path, size_t max_bytes);

}  // namespace adse::pool

#endif  // ADSE_HARNESS_POOL_CHILD_LOG_H_
