#include <fftw3.h>
#include <string>

namespace capsflow::fmm {
// FFTW's own version string, for `capsflow --version` and run metadata.
std::string fftw_version_string() { return fftw_version; }
}  // namespace capsflow::fmm
