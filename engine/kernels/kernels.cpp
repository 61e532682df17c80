// Which kernels run: the CPU's best path, or the one HAMILTONE_ISA names.
#include "kernels/kernels.h"

#include <cstdlib>
#include <stdexcept>

namespace hamiltone {

namespace portable {
extern const Kernels kernels;
}
#if defined(__x86_64__)
namespace avx2 {
extern const Kernels kernels;
}
namespace avx512 {
extern const Kernels kernels;
}
#endif

namespace {

constexpr Isa kEveryIsa[] = {Isa::portable, Isa::avx2, Isa::avx512};

const char* nameOf(Isa isa) {
  switch (isa) {
    case Isa::avx2:
      return "avx2";
    case Isa::avx512:
      return "avx512";
    default:
      return "portable";
  }
}

Isa bestIsa() {
  if (cpuRuns(Isa::avx512)) return Isa::avx512;
  if (cpuRuns(Isa::avx2)) return Isa::avx2;
  return Isa::portable;
}

}  // namespace

bool cpuRuns(Isa isa) {
#if defined(__x86_64__)
  __builtin_cpu_init();
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi2");
  switch (isa) {
    case Isa::avx2:
      return v3;
    case Isa::avx512:
      return v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512cd");
    default:
      return true;
  }
#else
  return isa == Isa::portable;
#endif
}

std::string isaNames() {
  std::string names;
  for (Isa isa : kEveryIsa) names += std::string(names.empty() ? "" : ", ") + nameOf(isa);
  return names;
}

const Kernels& kernelsFor(Isa isa) {
  if (!cpuRuns(isa))
    throw std::runtime_error(std::string("instruction set ") + nameOf(isa) +
                             ": this CPU does not run it (it runs " + nameOf(bestIsa()) + ")");
#if defined(__x86_64__)
  if (isa == Isa::avx512) return avx512::kernels;
  if (isa == Isa::avx2) return avx2::kernels;
#endif
  return portable::kernels;
}

const Kernels& kernelsNamed(std::string_view name) {
  for (Isa isa : kEveryIsa)
    if (name == nameOf(isa)) return kernelsFor(isa);
  throw std::runtime_error("instruction set \"" + std::string(name) + "\": must be one of " +
                           isaNames());
}

const Kernels& selectedKernels() {
  static const Kernels& chosen = []() -> const Kernels& {
    const char* wanted = std::getenv("HAMILTONE_ISA");
    if (!wanted || !*wanted) return kernelsFor(bestIsa());
    try {
      return kernelsNamed(wanted);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("HAMILTONE_ISA: ") + e.what() +
                               " (or unset: the best this CPU runs)");
    }
  }();
  return chosen;
}

}  // namespace hamiltone
