// Errors that reach the user. InputError is bad input (a world, a module type, a command line):
// its message already names the file and line; the app turns it into exit code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace rm3d {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rm3d
