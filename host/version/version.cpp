#include "clfractal/version.hpp"

namespace clfractal {

const char* version() { return CLFRACTAL_VERSION_STRING; }

}  // namespace clfractal
