// HAMILTONE_NONBLOCKING marks a function that must not allocate, lock or block:
// [[clang::nonblocking]] where Clang has it (20 and later), else nothing. Built with
// -fsanitize=realtime (tests/rtsan), a function so marked runs in RealtimeSanitizer's real-time
// context, where any such call is reported.
#pragma once

#if defined(__clang__) && __clang_major__ >= 20
#define HAMILTONE_NONBLOCKING [[clang::nonblocking]]
#else
#define HAMILTONE_NONBLOCKING
#endif
