#pragma once
/** \file progress.h
 * A terminal progress bar for long runs, drawn on stderr so that stdout
 * stays machine-readable (JSON Lines, tables). Quiet when stderr is not a
 * terminal except for a line every 10%, so that CI logs stay short.
 */
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace codemark::app
{
class ProgressBar
{
   public:
	explicit ProgressBar(std::string label, bool enabled = true)
		: label_(std::move(label)),
		  enabled_(enabled),
		  tty_(isatty(fileno(stderr)) != 0),
		  start_(std::chrono::steady_clock::now())
	{
	}
	~ProgressBar() { finish(); }

	/** Reports \a done of \a total units. */
	void update(long done, long total)
	{
		if (!enabled_ || total <= 0) return;
		done_ = done;
		const int pct = static_cast<int>(100.0 * done / total);
		if (!tty_)
		{
			if (pct / 10 > last_decile_ || done == total)
			{
				last_decile_ = pct / 10;
				std::fprintf(stderr, "%s: %ld/%ld (%d%%)\n", label_.c_str(), done, total, pct);
			}
			return;
		}
		const double el =
			std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
		const double eta = done > 0 ? el * (total - done) / done : 0;
		const int width = 30, fill = width * done / total;
		std::fprintf(
			stderr, "\r%s [%s%s] %3d%% %ld/%ld  %.0fs left ", label_.c_str(),
			std::string(fill, '#').c_str(), std::string(width - fill, '.').c_str(), pct, done,
			total, eta);
		std::fflush(stderr);
		drawn_ = true;
	}

	void finish()
	{
		if (drawn_ && tty_) std::fprintf(stderr, "\n");
		drawn_ = false;
	}

   private:
	std::string label_;
	bool enabled_, tty_;
	std::chrono::steady_clock::time_point start_;
	long done_ = 0;
	int last_decile_ = -1;
	bool drawn_ = false;
};
}  // namespace codemark::app
