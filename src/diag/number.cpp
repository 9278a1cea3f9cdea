#include "diag/number.h"

#include <cstdio>

namespace eamos::diag {

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace eamos::diag
