// libFuzzer target for one of msfem's input readers, chosen at compile time (MSFEM_FUZZ_OBJ, _STL,
// _OFF, _PLY, _CASE). A reader may refuse an input only with cases::InputError; anything else (a
// crash, a hang, a sanitizer report, another exception, or a surface it returns with an index out
// of range or a non-finite coordinate) is a defect the fuzzer reports.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>
#include <string_view>

#include "msfem/cases/errors.hpp"
#include "surface_io_detail.hpp"
#ifdef MSFEM_FUZZ_CASE
#include "case_file_text.hpp"
#endif

namespace {

using msfem::cases::Surface;

void check(const Surface& s) {
  if (!s.vertices.allFinite()) std::abort();
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (s.triangles(t, k) < 0 || s.triangles(t, k) >= s.vertices.rows()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
#if defined(MSFEM_FUZZ_OBJ)
    check(msfem::cases::detail::read_obj("fuzz.obj", bytes));
#elif defined(MSFEM_FUZZ_STL)
    check(msfem::cases::detail::read_stl("fuzz.stl", bytes));
#elif defined(MSFEM_FUZZ_OFF)
    check(msfem::cases::detail::read_off("fuzz.off", bytes));
#elif defined(MSFEM_FUZZ_PLY)
    check(msfem::cases::detail::read_ply("fuzz.ply", bytes));
#elif defined(MSFEM_FUZZ_CASE)
    // The language's sections as the case reader passes them; includes resolve under /nonexistent
    // so the fuzzer cannot make the target read the machine's files.
    static const std::set<std::string> sections = {
        "geometry", "material", "support", "loads", "loads/tool", "loads/patch force", "fem"};
    msfem::cases::checked_case_text("/nonexistent/fuzz.prm", std::string(bytes), sections);
#endif
  } catch (const msfem::cases::InputError&) {
    // a refused input, named: what a reader must do with bad bytes
  }
  return 0;
}
