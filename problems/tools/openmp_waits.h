// How long the program's OpenMP threads spin before they sleep.
//
// libgomp lets a thread that reaches a barrier first spin (up to 300 000
// polls of the barrier) before it sleeps. On cores shared with other work a
// spinning thread holds a core that its team-mate needs, and a solve with 2
// threads on 2 busy cores runs many times slower than on idle ones. The
// program therefore runs with a short spin (GOMP_SPINCOUNT, see
// docs/benchmarks.md "Threads" for the measured trade) unless the user set
// OMP_WAIT_POLICY or GOMP_SPINCOUNT. libgomp reads them when it loads, before
// main, so the program re-executes itself once with the setting added.
#pragma once

#include <string>

namespace diffpd::problems {

// The spin count the program sets (GOMP_SPINCOUNT's value).
extern const char* const kProgramSpinCount;

// Returns at once if OMP_WAIT_POLICY or GOMP_SPINCOUNT is set; otherwise sets
// GOMP_SPINCOUNT and re-executes the running program (/proc/self/exe) with
// `argv`. Returns only if that is not possible (the program then runs with
// libgomp's default).
void UseShortOpenMpWaits(char** argv);

// The wait settings in effect, for labelling measurements:
// "GOMP_SPINCOUNT=1000", "OMP_WAIT_POLICY=passive" (both, comma-separated,
// if both are set) or "OpenMP default waits".
std::string OpenMpWaitsLabel();

}  // namespace diffpd::problems
