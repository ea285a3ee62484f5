// Result<T>: a value or an Error. Bad data is a returned Error; broken invariants are asserts.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace dpoint {

// Exit codes of the dpoint executable (DESIGN §1). Library errors carry the code the CLI exits with.
enum class ExitCode : int {
  kOk = 0,
  kUsage = 1,
  kBadInput = 2,
  kNoDevice = 3,
  kResourceLimit = 4,
  kInterrupted = 130,  // SIGINT (128 + 2), as shells report it
  kTerminated = 143,   // SIGTERM (128 + 15)
};

struct Error {
  std::string message;  // one line naming the file, line/offset, column/field and the bad value
  ExitCode code = ExitCode::kBadInput;
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}             // NOLINT: implicit by design
  Result(Error error) : data_(std::move(error)) {}         // NOLINT: implicit by design

  bool ok() const { return data_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { assert(ok()); return std::get<0>(data_); }
  const T& value() const& { assert(ok()); return std::get<0>(data_); }
  T&& value() && { assert(ok()); return std::get<0>(std::move(data_)); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }

  const Error& error() const { assert(!ok()); return std::get<1>(data_); }

 private:
  std::variant<T, Error> data_;
};

// For operations that return nothing but may fail.
struct Unit {};
using Status = Result<Unit>;
inline Status okStatus() { return Unit{}; }

}  // namespace dpoint
