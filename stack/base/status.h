// Explicit error values passed up plainly. Exceptions from third-party
// libraries are caught at the edge of the module that uses them and turned
// into a Status.
#ifndef ADSE_STACK_BASE_STATUS_H_
#define ADSE_STACK_BASE_STATUS_H_

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace adse {

class Status {
 public:
  enum class Code {
    kOk = 0,
    kInvalidArgument,  // bad user input: a scenario, a flag, a point
    kNotFound,         // a named file or object does not exist
    kCorruption,       // a file exists but its content is broken
    kIoError,          // the filesystem or a child process failed
    kUnavailable,      // a service or resource cannot be had now
    kInternal,         // a bug in adse
  };

  Status() = default;
  static Status Ok() { return Status(); }
  static Status InvalidArgument(std::string msg) {
    return Status(Code::kInvalidArgument, std::move(msg));
  }
  static Status NotFound(std::string msg) {
    return Status(Code::kNotFound, std::move(msg));
  }
  static Status Corruption(std::string msg) {
    return Status(Code::kCorruption, std::move(msg));
  }
  static Status IoError(std::string msg) {
    return Status(Code::kIoError, std::move(msg));
  }
  static Status Unavailable(std::string msg) {
    return Status(Code::kUnavailable, std::move(msg));
  }
  static Status Internal(std::string msg) {
    return Status(Code::kInternal, std::move(msg));
  }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  const std::string& message() const { return message_; }
  // "Invalid argument: <message>" style text for logs.
  std::string ToString() const;
  // Prefixes the message with context ("loading map: ...").
  Status WithContext(const std::string& context) const;

 private:
  Status(Code code, std::string msg) : code_(code), message_(std::move(msg)) {}
  Code code_ = Code::kOk;
  std::string message_;
};

// Process exit code for a status: 0 ok, 2 bad input, 1 anything else.
int ExitCodeFor(const Status& status);

// A value or the Status that explains why there is none.
template <typename T>
class Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT: implicit on purpose
  Result(Status status) : data_(std::move(status)) {}  // NOLINT

  bool ok() const { return std::holds_alternative<T>(data_); }
  const Status& status() const {
    static const Status kOk;
    return ok() ? kOk : std::get<Status>(data_);
  }
  T& value() & { return std::get<T>(data_); }
  const T& value() const& { return std::get<T>(data_); }
  T&& value() && { return std::get<T>(std::move(data_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

 private:
  std::variant<T, Status> data_;
};

}  // namespace adse

// Returns early from the enclosing function when `expr` is not ok.
#define ADSE_RETURN_IF_ERROR(expr)               \
  do {                                           \
    ::adse::Status adse_status_ = (expr);        \
    if (!adse_status_.ok()) return adse_status_; \
  } while (0)

#endif  // ADSE_STACK_BASE_STATUS_H_
