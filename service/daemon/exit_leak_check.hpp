#pragma once
// The end-of-process leak check of a sanitizer build, taken at a quiet moment.
//
// LeakSanitizer checks for leaks in an exit handler, after static destructors have run. By then
// OpenCV's thread library (TBB) has told its worker threads to end without waiting for them, and
// a thread that ends while the check suspends the process can crash the check ("Tracer caught
// signal 11", seen once in a thousand-part run of facetd). Returning from main through
// checkLeaksNow() checks while every thread is either joined or idle; the exit handler then
// does nothing. Without a sanitizer this is a no-op.

#if defined(__SANITIZE_ADDRESS__)
#define FACET_LEAK_CHECK 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FACET_LEAK_CHECK 1
#endif
#endif

#ifdef FACET_LEAK_CHECK
#include <sanitizer/lsan_interface.h>
#endif

namespace facet::service {

// Call after main's own objects are gone and its threads joined; returns `exitCode`.
inline int checkLeaksNow(int exitCode) {
#ifdef FACET_LEAK_CHECK
  __lsan_do_leak_check();
#endif
  return exitCode;
}

}  // namespace facet::service
