// SPDX-License-Identifier: GPL-3.0-or-later
//
// The X display that off-screen VTK pictures are drawn on. Debian's VTK 9.1
// renders through GLX only, so even off-screen rendering needs an X server:
// the one named by DISPLAY when it works, otherwise a private Xvfb started at
// first use and stopped when the process ends (even when it crashes).
#pragma once

#include <functional>
#include <mutex>
#include <string>

namespace pcl_ms_tools {

// Tells whether OpenGL renders on an Xlib display (a Display *), else gives a
// one-line reason in `error`.
using DisplayCheck = std::function<bool(void *display, std::string &error)>;

// One render's hold on the display. It serializes renders, because VTK's
// OpenGL state and the shared Xlib connection are not thread-safe, and it
// records X protocol errors, which Xlib's default handler answers by exiting
// the process.
class OffscreenSession {
public:
  OffscreenSession();
  ~OffscreenSession();
  OffscreenSession(const OffscreenSession &) = delete;
  OffscreenSession &operator=(const OffscreenSession &) = delete;

  // The process's X display as an Xlib Display *, or nullptr with a one-line
  // reason in `error`. The first call in the process picks it: DISPLAY if it
  // opens, has GLX and passes `check`, else a private Xvfb that must pass
  // `check`. The choice, or the failure, stays for the process.
  void *display(const DisplayCheck &check, std::string &error);

  // The first X protocol error of this session, or "" when there was none.
  std::string xError() const;

private:
  std::unique_lock<std::mutex> lock_;
  void *display_ = nullptr;
};

} // namespace pcl_ms_tools
