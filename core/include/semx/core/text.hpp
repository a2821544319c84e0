// Numbers in messages meant for people (reasons, errors): the few digits that say it.
#pragma once

#include <sstream>
#include <string>

namespace semx::core {

// `v` with `significant` significant digits, as an ostream prints it (0.123, 1.5e+03).
inline std::string short_number(double v, int significant = 3) {
  std::ostringstream s;
  s.precision(significant);
  s << v;
  return s.str();
}

}  // namespace semx::core
