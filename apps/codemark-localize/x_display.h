#pragma once
// Kept apart from MRPT's headers: Xlib's macros (None, Bool, ...) clash with them.
namespace codemark::app
{
/** Throws std::runtime_error (one line) unless an X display can be opened:
 * wxWidgets aborts the process when it cannot open one, so check first. */
void requireDisplay();
}  // namespace codemark::app
