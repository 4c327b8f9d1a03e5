#include "src/core/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>

namespace nave {
namespace {

// What is kept of the child's stderr: enough for a library's assertion message, not a flood.
constexpr size_t kStderrTailBytes = 4096;

// Both ends of a pipe, closed on destruction. O_CLOEXEC so that a program another thread starts
// meanwhile does not inherit them (and keep the pipe open past the child's end).
struct Pipe {
    int fd[2] = {-1, -1};
    Status Open() {
        if (::pipe2(fd, O_CLOEXEC) != 0)
            return IoError("cannot create a pipe: {}", std::strerror(errno));
        return Status::Ok();
    }
    void Close(int end) {
        if (fd[end] >= 0) ::close(fd[end]);
        fd[end] = -1;
    }
    ~Pipe() {
        Close(0);
        Close(1);
    }
};

// The first number of /proc/self/statm (the process's virtual size, in pages) or MemAvailable of
// /proc/meminfo, in bytes; 0 if unreadable.
uint64_t VirtualSizeBytes() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (f == nullptr) return 0;
    unsigned long long pages = 0;
    const int got = std::fscanf(f, "%llu", &pages);
    std::fclose(f);
    return got == 1 ? pages * uint64_t(::sysconf(_SC_PAGE_SIZE)) : 0;
}

uint64_t AvailableMemoryBytes() {
    std::FILE* f = std::fopen("/proc/meminfo", "r");
    if (f == nullptr) return 0;
    char line[256];
    unsigned long long kib = 0;
    while (std::fgets(line, sizeof(line), f) != nullptr) {
        if (std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1) break;
    }
    std::fclose(f);
    return kib * 1024;
}

}  // namespace

uint64_t ChildAddressSpaceLimitBytes() {
    const uint64_t available = AvailableMemoryBytes();
    return available == 0 ? 0 : VirtualSizeBytes() + available;
}

bool WriteAllToFd(int fd, const void* data, size_t size) {
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= size_t(n);
    }
    return true;
}

std::string DescribeSignal(int signal) {
    const char* name = ::strsignal(signal);
    return "signal " + std::to_string(signal) + ": " + (name != nullptr ? name : "unknown");
}

int ReportStatusFromChild(int fd, const Status& status) {
    const std::string& message = status.message();
    WriteAllToFd(fd, message.data(), message.size());
    return kChildStatusExitBase + int(status.code());
}

bool ChildReportedStatus(const ChildOutcome& child, Status* reported) {
    const int code = child.exit_code - kChildStatusExitBase;
    if (!child.exited || code <= int(StatusCode::kOk) || code > int(StatusCode::kInternal)) {
        return false;
    }
    *reported = Status(StatusCode(code), child.output);
    return true;
}

std::string DescribeChildEnd(const ChildOutcome& child) {
    return child.exited ? "exited with code " + std::to_string(child.exit_code)
                        : "crashed (" + DescribeSignal(child.signal) + ")";
}

StatusOr<ChildOutcome> RunInChildProcess(const std::function<int(int output_fd)>& work,
                                         double time_limit_seconds) {
    Pipe out, err;
    NAVE_RETURN_IF_ERROR(out.Open());
    NAVE_RETURN_IF_ERROR(err.Open());
    // Read before the fork: the child should only run its work.
    const uint64_t address_space = ChildAddressSpaceLimitBytes();
    const pid_t pid = ::fork();
    if (pid < 0) return IoError("cannot start a child process: {}", std::strerror(errno));
    if (pid == 0) {
        ::close(out.fd[0]);
        ::close(err.fd[0]);
        ::dup2(err.fd[1], STDERR_FILENO);
        // The parent's handlers (a crash reporter, a sanitizer, libFuzzer's) must not turn the
        // child's crash into an orderly exit: the parent learns of it from the signal.
        for (int s : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGPIPE, SIGXCPU})
            std::signal(s, SIG_DFL);
        // The parent reports the crash; a core file of it would only litter the user's directory.
        const rlimit no_core = {0, 0};
        ::setrlimit(RLIMIT_CORE, &no_core);
        // A library that believes a damaged count (Assimp reserving 10^8 faces of a 40-byte OFF
        // file) fails an allocation (bad_alloc, which Assimp reports as an error) instead of taking
        // the machine's memory until the kernel's OOM killer picks a victim, maybe not this child.
        rlimit as{};
        if (address_space > 0 && ::getrlimit(RLIMIT_AS, &as) == 0) {
            as.rlim_cur = std::min<rlim_t>(as.rlim_max, rlim_t(address_space));
            ::setrlimit(RLIMIT_AS, &as);
        }
        if (time_limit_seconds > 0) {
            // SIGXCPU at the soft limit ends the child (default action); the hard limit a little
            // later is the kernel's SIGKILL should something catch SIGXCPU after all.
            const auto cpu_seconds = rlim_t(std::ceil(time_limit_seconds));
            const rlimit cpu = {cpu_seconds, cpu_seconds + 2};
            ::setrlimit(RLIMIT_CPU, &cpu);
        }
        int code = 125;
        try {
            code = work(out.fd[1]);
        } catch (...) {
            // An exception must not unwind into the parent's copy of the stack.
        }
        ::_exit(code);
    }
    out.Close(1);
    err.Close(1);

    ChildOutcome outcome;
    pollfd fds[2] = {{out.fd[0], POLLIN, 0}, {err.fd[0], POLLIN, 0}};
    int open_fds = 2;
    char buffer[1 << 16];
    // The wall-clock deadline catches a child that is blocked rather than spinning; twice the CPU
    // limit leaves room for a child that shares the cores with other work.
    using Clock = std::chrono::steady_clock;
    const bool limited = time_limit_seconds > 0;
    const Clock::time_point deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(2 * time_limit_seconds + 1));
    while (open_fds > 0) {
        int timeout_ms = -1;
        if (limited) {
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            if (left.count() <= 0) {
                ::kill(pid, SIGKILL);
                outcome.timed_out = true;
                break;  // its pipes close with the Pipe objects; waitpid below reaps it
            }
            timeout_ms = int(std::min<int64_t>(left.count() + 1, 60'000));
        }
        const int ready = ::poll(fds, 2, timeout_ms);
        if (ready == 0) continue;  // the deadline is checked above
        if (ready < 0) {
            if (errno == EINTR) continue;
            break;  // cannot happen with valid descriptors; waitpid below still reaps the child
        }
        for (int i = 0; i < 2; ++i) {
            if (fds[i].fd < 0 || fds[i].revents == 0) continue;
            const ssize_t n = ::read(fds[i].fd, buffer, sizeof(buffer));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                fds[i].fd = -1;  // poll ignores negative descriptors; the Pipe closes it
                --open_fds;
                continue;
            }
            std::string& to = i == 0 ? outcome.output : outcome.stderr_tail;
            to.append(buffer, size_t(n));
            if (i == 1 && to.size() > 2 * kStderrTailBytes)
                to.erase(0, to.size() - kStderrTailBytes);
        }
    }
    if (outcome.stderr_tail.size() > kStderrTailBytes)
        outcome.stderr_tail.erase(0, outcome.stderr_tail.size() - kStderrTailBytes);

    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR)
            return IoError("cannot wait for child process {}: {}", pid, std::strerror(errno));
    }
    if (WIFEXITED(status)) {
        outcome.exited = true;
        outcome.exit_code = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
        outcome.signal = WTERMSIG(status);
        if (limited && outcome.signal == SIGXCPU) outcome.timed_out = true;
    }
    return outcome;
}

}  // namespace nave
