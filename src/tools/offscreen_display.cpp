// SPDX-License-Identifier: GPL-3.0-or-later
#include "offscreen_display.h"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

namespace pcl_ms_tools {
namespace {

constexpr int kXvfbStartTimeoutMs = 20000;
constexpr int kXvfbStopTimeoutMs = 2000;
// Xvfb writes its display number to this descriptor once it accepts clients.
constexpr int kDisplayNumberFd = 3;

std::string systemError(const std::string &what) { return what + ": " + std::strerror(errno); }

void closeDescriptor(int &fd) {
  if (fd >= 0)
    ::close(fd);
  fd = -1;
}

// Full path of `program` found through PATH, or "" when it is not there.
std::string findInPath(const std::string &program) {
  const char *path = std::getenv("PATH");
  std::stringstream directories(path ? path : "");
  std::string directory;
  while (std::getline(directories, directory, ':')) {
    if (directory.empty())
      continue;
    const std::string candidate = directory + "/" + program;
    if (::access(candidate.c_str(), X_OK) == 0)
      return candidate;
  }
  return "";
}

// The last non-empty line of the file behind `fd`, for error messages.
std::string lastLine(int fd) {
  std::string text;
  char buffer[4096];
  off_t offset = 0;
  ssize_t count;
  while ((count = ::pread(fd, buffer, sizeof buffer, offset)) > 0) {
    text.append(buffer, static_cast<std::size_t>(count));
    offset += count;
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == ' '))
    text.pop_back();
  const std::size_t start = text.find_last_of('\n');
  return start == std::string::npos ? text : text.substr(start + 1);
}

// --- Runs in forked children: async-signal-safe calls only, because the
// --- parent may have other threads whose locks are frozen in the copy.

void resetSignals() {
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  for (int signal : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGCHLD})
    ::sigaction(signal, &action, nullptr);
  sigset_t none;
  ::sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
}

// Closes every inherited descriptor above stderr except the ones kept.
void closeOtherDescriptors(std::array<int, 3> keep) {
  std::sort(keep.begin(), keep.end());
  unsigned first = 3;
  for (const int kept : keep) {
    const unsigned keep_fd = static_cast<unsigned>(kept);
    if (keep_fd > first)
      ::close_range(first, keep_fd - 1, 0);
    first = std::max(first, keep_fd + 1);
  }
  ::close_range(first, ~0U, 0);
}

void sleepMilliseconds(long milliseconds) {
  timespec duration{milliseconds / 1000, (milliseconds % 1000) * 1000000};
  while (::nanosleep(&duration, &duration) < 0 && errno == EINTR) {
  }
}

[[noreturn]] void execXvfb(const char *xvfb, char *const argv[], int ready_write, int log) {
  // Move the descriptors out of the way first so no dup2 below clobbers one.
  const int high_log = ::fcntl(log, F_DUPFD_CLOEXEC, 10);
  const int high_ready = ::fcntl(ready_write, F_DUPFD_CLOEXEC, 10);
  const int null_input = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (high_log < 0 || high_ready < 0 || null_input < 0)
    ::_exit(127);
  ::dup2(null_input, 0);
  ::dup2(high_log, 1);
  ::dup2(high_log, 2);
  ::dup2(high_ready, kDisplayNumberFd);
  ::execv(xvfb, argv);
  ::_exit(127);
}

// The watchdog between the owner process and Xvfb: it holds the read end of
// the lifeline pipe, whose write end only the owner has. The pipe reads EOF
// as soon as the owner is gone, however it ended (exit, abort, SIGKILL), and
// then the watchdog stops Xvfb, so no X server outlives its owner.
[[noreturn]] void superviseXvfb(const char *xvfb, char *const argv[], int lifeline_read,
                                int lifeline_write, int ready_write, int log) {
  resetSignals();
  ::close(lifeline_write);
  closeOtherDescriptors({lifeline_read, ready_write, log});

  const pid_t server = ::fork();
  if (server == 0) {
    ::close(lifeline_read);
    execXvfb(xvfb, argv, ready_write, log);
  }
  // Only Xvfb reports readiness: the owner sees EOF if it dies first.
  ::close(ready_write);
  ::close(log);
  if (server < 0)
    ::_exit(1);

  pollfd lifeline{lifeline_read, POLLIN, 0};
  while (::poll(&lifeline, 1, -1) < 0 && errno == EINTR) {
  }
  ::kill(server, SIGTERM);
  for (long waited = 0;; waited += 10) {
    const pid_t reaped = ::waitpid(server, nullptr, WNOHANG);
    if (reaped == server || (reaped < 0 && errno != EINTR))
      break;
    if (waited >= kXvfbStopTimeoutMs) {
      ::kill(server, SIGKILL);
      ::waitpid(server, nullptr, 0);
      break;
    }
    sleepMilliseconds(10);
  }
  ::_exit(0);
}

// --- Parent side.

// A private Xvfb on a free display number, with a watchdog process that stops
// it when this process ends.
class PrivateXServer {
public:
  PrivateXServer() = default;
  PrivateXServer(const PrivateXServer &) = delete;
  PrivateXServer &operator=(const PrivateXServer &) = delete;
  ~PrivateXServer() {
    // A forked copy of this process does not own the server.
    if (::getpid() == owner_)
      stop();
  }

  bool start(std::string &error) {
    const std::string xvfb = findInPath("Xvfb");
    if (xvfb.empty()) {
      error = "Xvfb is not installed (Debian package xvfb)";
      return false;
    }
    std::string log_path = (std::filesystem::temp_directory_path() / "pcl_ms_xvfb_XXXXXX").string();
    int log = ::mkostemp(log_path.data(), O_CLOEXEC);
    if (log < 0) {
      error = systemError("cannot create a log file for Xvfb in " + log_path);
      return false;
    }
    ::unlink(log_path.c_str()); // nothing to clean up later; the descriptor keeps it
    int ready[2];
    int lifeline[2];
    if (::pipe2(ready, O_CLOEXEC) != 0) {
      error = systemError("cannot create a pipe for Xvfb");
      ::close(log);
      return false;
    }
    if (::pipe2(lifeline, O_CLOEXEC) != 0) {
      error = systemError("cannot create a pipe for Xvfb");
      ::close(log);
      ::close(ready[0]);
      ::close(ready[1]);
      return false;
    }

    // Built before fork: the children must not allocate. The screen size
    // does not limit the pictures, which are drawn in off-screen framebuffers.
    std::vector<std::string> arguments{xvfb,        "-displayfd", std::to_string(kDisplayNumberFd),
                                       "-screen",   "0",          "1920x1080x24",
                                       "-nolisten", "tcp",        "-noreset"};
    std::vector<char *> argv;
    for (std::string &argument : arguments)
      argv.push_back(argument.data());
    argv.push_back(nullptr);

    const pid_t watchdog = ::fork();
    if (watchdog == 0)
      superviseXvfb(xvfb.c_str(), argv.data(), lifeline[0], lifeline[1], ready[1], log);
    ::close(ready[1]);
    ::close(lifeline[0]);
    if (watchdog < 0) {
      error = systemError("cannot start Xvfb");
      ::close(lifeline[1]);
      ::close(ready[0]);
      ::close(log);
      return false;
    }
    watchdog_ = watchdog;
    lifeline_ = lifeline[1];

    bool timed_out = false;
    const std::string number = readDisplayNumber(ready[0], timed_out);
    ::close(ready[0]);
    if (number.empty()) {
      stop();
      const std::string reason = lastLine(log);
      error = std::string("Xvfb did not start") + (timed_out ? " in time" : "") +
              (reason.empty() ? "" : ": " + reason);
      ::close(log);
      return false;
    }
    ::close(log);
    display_name_ = ":" + number;
    return true;
  }

  const std::string &displayName() const { return display_name_; }

private:
  // The digits Xvfb writes when ready, or "" on EOF or timeout.
  static std::string readDisplayNumber(int fd, bool &timed_out) {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline =
        Clock::now() + std::chrono::milliseconds(kXvfbStartTimeoutMs);
    std::string text;
    while (text.find('\n') == std::string::npos) {
      const auto remaining =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (remaining <= 0) {
        timed_out = true;
        return "";
      }
      pollfd readable{fd, POLLIN, 0};
      const int polled = ::poll(&readable, 1, static_cast<int>(remaining));
      if (polled < 0 && errno != EINTR)
        return "";
      if (polled <= 0)
        continue; // interrupted, or the deadline check above ends the wait
      char buffer[64];
      const ssize_t count = ::read(fd, buffer, sizeof buffer);
      if (count < 0 && errno == EINTR)
        continue;
      if (count <= 0)
        return "";
      text.append(buffer, static_cast<std::size_t>(count));
    }
    text.erase(text.find('\n'));
    const bool digits = !text.empty() && std::all_of(text.begin(), text.end(),
                                                     [](char c) { return c >= '0' && c <= '9'; });
    return digits ? text : "";
  }

  void stop() {
    closeDescriptor(lifeline_); // the watchdog sees EOF and stops Xvfb
    if (watchdog_ > 0) {
      while (::waitpid(watchdog_, nullptr, 0) < 0 && errno == EINTR) {
      }
      watchdog_ = -1;
    }
  }

  pid_t owner_ = ::getpid();
  pid_t watchdog_ = -1;
  int lifeline_ = -1;
  std::string display_name_;
};

bool hasGlx(Display *display) {
  int opcode = 0;
  int event = 0;
  int error = 0;
  return XQueryExtension(display, "GLX", &opcode, &event, &error);
}

// The first X protocol error since the trap was armed. Xlib's default
// handler exits the process on any error, and GLX reports failures that way
// (for instance BadValue from glXCreateContext under indirect rendering).
std::string first_x_error;              // guarded by the rendering mutex
XErrorHandler previous_x_error_handler; // likewise

int recordXError(Display *display, XErrorEvent *event) {
  if (first_x_error.empty()) {
    char text[256] = "";
    XGetErrorText(display, event->error_code, text, sizeof text);
    first_x_error = std::string("X error ") + text + " (request " +
                    std::to_string(static_cast<int>(event->request_code)) + "." +
                    std::to_string(static_cast<int>(event->minor_code)) + ")";
  }
  return 0;
}

// Waits for the server's answers, so errors of earlier requests are in.
std::string pendingXError(Display *display) {
  XSync(display, False);
  return first_x_error;
}

// Opens `name` and keeps it if OpenGL renders there.
// `glx_hint` is added to the message when the display has no GLX.
Display *openUsableDisplay(const std::string &name, const std::string &description,
                           const std::string &glx_hint, const DisplayCheck &check,
                           std::string &error) {
  Display *display = XOpenDisplay(name.c_str());
  if (!display) {
    error = "cannot open " + description;
    return nullptr;
  }
  if (!hasGlx(display)) {
    error = description + " has no GLX extension" + glx_hint;
    XCloseDisplay(display);
    return nullptr;
  }
  std::string reason;
  const bool works = check(display, reason);
  const std::string x_error = pendingXError(display);
  if (!works || !x_error.empty()) {
    error = "no OpenGL on " + description + ": " + (x_error.empty() ? reason : x_error);
    XCloseDisplay(display);
    return nullptr;
  }
  return display;
}

// What the first render decided, for the rest of the process.
struct DisplayChoice {
  bool decided = false;
  Display *display = nullptr;
  std::string failure;
  std::unique_ptr<PrivateXServer> server;
  pid_t owner = ::getpid();

  DisplayChoice() = default;
  DisplayChoice(const DisplayChoice &) = delete;
  DisplayChoice &operator=(const DisplayChoice &) = delete;
  ~DisplayChoice() {
    // A forked copy must not talk over the parent's connection.
    if (::getpid() != owner)
      return;
    // Close the connection before the server goes away.
    if (display)
      XCloseDisplay(display);
    server.reset();
  }

  void decide(const DisplayCheck &check) {
    decided = true;
    std::string display_failure = "DISPLAY is not set";
    const char *display_variable = std::getenv("DISPLAY");
    if (display_variable && *display_variable)
      display = openUsableDisplay(display_variable,
                                  std::string("X display ") + display_variable + " (DISPLAY)", "",
                                  check, display_failure);
    if (display)
      return;
    std::string server_failure;
    auto private_server = std::make_unique<PrivateXServer>();
    if (private_server->start(server_failure))
      // Xvfb's GLX needs Mesa's DRI drivers; without them it starts without GLX.
      display = openUsableDisplay(
          private_server->displayName(), "the private Xvfb " + private_server->displayName(),
          " (Debian package libgl1-mesa-dri missing?)", check, server_failure);
    if (display)
      server = std::move(private_server);
    else
      failure = display_failure + ", and " + server_failure;
  }
};

DisplayChoice &displayChoice() {
  static DisplayChoice choice;
  return choice;
}

std::mutex &renderingMutex() {
  static std::mutex mutex;
  return mutex;
}

} // namespace

OffscreenSession::OffscreenSession() : lock_(renderingMutex()) {
  first_x_error.clear();
  previous_x_error_handler = XSetErrorHandler(&recordXError);
}

OffscreenSession::~OffscreenSession() {
  // Errors still in flight must reach our handler, not the exiting default.
  if (display_)
    XSync(static_cast<Display *>(display_), False);
  XSetErrorHandler(previous_x_error_handler);
}

void *OffscreenSession::display(const DisplayCheck &check, std::string &error) {
  DisplayChoice &choice = displayChoice();
  if (!choice.decided)
    choice.decide(check);
  if (!choice.display)
    error = choice.failure;
  display_ = choice.display;
  return display_;
}

std::string OffscreenSession::xError() const {
  return display_ ? pendingXError(static_cast<Display *>(display_)) : first_x_error;
}

} // namespace pcl_ms_tools
