#include "x_display.h"

#include <X11/Xlib.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace codemark::app
{
void requireDisplay()
{
	const char* d = std::getenv("DISPLAY");
	if (!d || !*d)
		throw std::runtime_error(
			"--gui: no display (DISPLAY is not set); run without --gui, or under xvfb-run -a");
	Display* x = XOpenDisplay(nullptr);
	if (!x)
		throw std::runtime_error(
			std::string("--gui: cannot open display '") + d +
			"'; run without --gui, or under xvfb-run -a");
	XCloseDisplay(x);
}
}  // namespace codemark::app
