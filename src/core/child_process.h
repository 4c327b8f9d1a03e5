#pragma once
// Running a piece of work in a forked child process, so that a library which aborts, asserts or
// crashes on bad input (Assimp's ai_assert calls abort()) takes down the child and not nave. The
// child sends its result back through a pipe; the parent learns whether it exited or which signal
// killed it, and reports that as a Status instead of dying.

#include <cstdint>
#include <functional>
#include <string>

#include "src/core/status.h"

namespace nave {

/// How a child process ended and what it sent.
struct ChildOutcome {
    std::string output;       ///< every byte the child wrote to its output descriptor
    std::string stderr_tail;  ///< the last few KiB it wrote to stderr (a library's last words)
    bool exited = false;      ///< it returned from its work (or called _exit)
    int exit_code = 0;        ///< when exited
    int signal = 0;           ///< when killed by a signal: its number
    bool timed_out = false;   ///< stopped for overrunning its time limit (signal says how)
};

/// Forks; the child runs `work(output_fd)` and `_exit`s with its return value without running
/// atexit handlers or static destructors (they belong to the parent's threads and state). The
/// parent collects the child's output and stderr until both close, then waits for it. In the child
/// the crash signals are reset to their defaults and core files are off, so a crash ends it at once
/// and is seen by the parent as that signal; its address space is capped
/// (ChildAddressSpaceLimitBytes).
///
/// `time_limit_seconds` > 0 bounds a child that never finishes (a library looping on a damaged
/// count): it may use that much CPU time (RLIMIT_CPU; SIGXCPU ends it), and the parent kills it
/// (SIGKILL) if it is still running twice that long plus a second after it started, which catches
/// a child blocked without using the CPU. Either way `timed_out` is set. 0 sets no limit.
///
/// Safe to call from a process with other threads (TBB's workers) as long as `work` only uses what
/// a freshly forked single thread may use: malloc (glibc and jemalloc reset their locks at fork),
/// files, and a library that starts no threads of its own. Errors: IoError when the pipe or the
/// fork fails; a crashing child is not an error here but an outcome.
StatusOr<ChildOutcome> RunInChildProcess(const std::function<int(int output_fd)>& work,
                                         double time_limit_seconds = 0);

/// The child's address-space limit (RLIMIT_AS): the parent's virtual size now plus the memory the
/// machine has available (MemAvailable), so that the work can use what is free but a runaway
/// allocation fails in the child rather than pushing the machine out of memory. 0 if unknown (no
/// limit is set then).
uint64_t ChildAddressSpaceLimitBytes();

/// Writes all of `size` bytes to `fd`, retrying short writes and EINTR. False on any other error.
bool WriteAllToFd(int fd, const void* data, size_t size);

/// For work that ends with a Status (the importers' children): a failure is reported by writing its
/// message to the output and exiting with kChildStatusExitBase + its code; success exits 0. Any
/// other end (a signal, another exit code) is the work's crash.
inline constexpr int kChildStatusExitBase = 64;

/// In the child: writes `status`'s message to `fd` and returns the exit code that reports it.
int ReportStatusFromChild(int fd, const Status& status);

/// In the parent: true, with the Status in `*reported`, when the child reported a failure as
/// ReportStatusFromChild does; false when it exited 0 or ended any other way.
bool ChildReportedStatus(const ChildOutcome& child, Status* reported);

/// How a child that did not succeed ended: "exited with code 3", "crashed (signal 11:
/// Segmentation fault)".
std::string DescribeChildEnd(const ChildOutcome& child);

/// "signal 6: Aborted": the number and the C library's description of it.
std::string DescribeSignal(int signal);

}  // namespace nave
