// Typed errors at crowddb's public boundary. Every failure a user can cause (a bad file, a bad
// argument, an invalid row) is reported as one of these, with a one-line message that names the
// file, line or field; the CLI prints what() and exits with exit_code().
#pragma once

#include <stdexcept>
#include <string>

namespace crowddb {

class Error : public std::runtime_error {
 public:
  enum class Kind {
    usage,  // bad command-line use: exit status 2
    input,  // malformed or invalid input data (files, rows, parameters): exit status 1
    io,     // the operating system refused (missing file, unwritable path): exit status 1
  };
  Error(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }
  int exit_code() const { return kind_ == Kind::usage ? 2 : 1; }

 private:
  Kind kind_;
};

// A row that would break a table's invariants (NaN, radius <= 0, unknown goal ...). `field` names
// the offending column so callers can add the file and row they read it from.
class InvalidRow : public Error {
 public:
  InvalidRow(std::string field, const std::string& message)
      : Error(Kind::input, message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace crowddb
