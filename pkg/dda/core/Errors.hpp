// The typed errors of the core (Python: ValueError, pkg/py/module.cpp). Each
// message names the offending index and value; nothing logs and carries on.
#pragma once

#include <stdexcept>

namespace dda {

// Raised for input that cannot be a DDA block. The message names the offending
// point index and value, e.g. "point 8 (0.5, 0.5, 0.5) lies strictly inside the
// hull of the others: the input is not convex".
class InputError : public std::invalid_argument {
public:
	using std::invalid_argument::invalid_argument;
};

// A saved state that cannot be read: truncated, corrupt, another format
// version or byte order (Python: ValueError).
class StateError : public std::invalid_argument {
public:
	using std::invalid_argument::invalid_argument;
};

}  // namespace dda
