#pragma once
/** \file progress.h
 * The progress display of every tool's long runs, on stderr so that stdout
 * stays machine-readable (JSON Lines, tables). On a terminal: one line
 * redrawn in place, with MRPT's bar (mrpt::system::progress), the count,
 * the rate and the time left. Otherwise (a log, CI): one line per 10%, and
 * the last line once, from finish(). The count never passes its total and
 * never goes back.
 */
#include <mrpt/system/progress.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

namespace codemark::app
{
class ProgressBar
{
   public:
	/** \a out: where to draw (stderr); \a tty: whether it is a terminal
	 * (default: asked of \a out). */
	explicit ProgressBar(
		std::string label, bool enabled = true, std::FILE* out = stderr,
		std::optional<bool> tty = std::nullopt)
		: label_(std::move(label)),
		  enabled_(enabled),
		  out_(out),
		  tty_(tty ? *tty : isatty(fileno(out)) != 0),
		  start_(std::chrono::steady_clock::now())
	{
	}
	/** A run that ends without finish() (an error) leaves no 100% line. */
	~ProgressBar()
	{
		if (drawn_ && tty_) std::fputc('\n', out_);
	}
	ProgressBar(const ProgressBar&) = delete;
	ProgressBar& operator=(const ProgressBar&) = delete;

	/** Reports \a done of \a total units (clamped to [last done, total]). */
	void update(long done, long total)
	{
		if (!enabled_ || finished_ || total <= 0) return;
		total_ = total;
		done_ = std::clamp(done, done_, total);
		if (!tty_)
		{
			// Deciles 1-9 here; the last line comes from finish().
			const int decile = static_cast<int>(10 * done_ / total_);
			if (decile > last_decile_ && done_ < total_)
			{
				last_decile_ = decile;
				std::fprintf(
					out_, "%s: %ld/%ld (%d%%)\n", label_.c_str(), done_, total_, 10 * decile);
				std::fflush(out_);
			}
			return;
		}
		// Redraw at most 10 times a second (and at the end).
		const auto now = std::chrono::steady_clock::now();
		if (drawn_ && done_ < total_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
		last_draw_ = now;
		draw(elapsed());
	}

	/** The run is done: its last line, once. */
	void finish()
	{
		if (!enabled_ || finished_) return;
		finished_ = true;
		const double el = elapsed();
		if (tty_)
		{
			if (total_ > 0) done_ = total_;
			if (total_ > 0) draw(el);
			std::fprintf(out_, "\n");
			drawn_ = false;
		}
		else if (total_ > 0)
			std::fprintf(
				out_, "%s: %ld/%ld (100%%) in %.1f s\n", label_.c_str(), total_, total_, el);
		std::fflush(out_);
	}

   private:
	double elapsed() const
	{
		return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
	}

	void draw(double el)
	{
		const double f = static_cast<double>(done_) / static_cast<double>(total_);
		const double rate = el > 0 ? static_cast<double>(done_) / el : 0.0;
		const double left = done_ > 0 ? el * static_cast<double>(total_ - done_) / done_ : 0.0;
		std::fprintf(
			out_, "\r%s %s %3d%% %ld/%ld  %.1f/s  %.0f s left ", label_.c_str(),
			mrpt::system::progress(f, 30).c_str(), static_cast<int>(100 * f), done_, total_, rate,
			left);
		std::fflush(out_);
		drawn_ = true;
	}

	std::string label_;
	bool enabled_;
	std::FILE* out_;
	bool tty_;
	std::chrono::steady_clock::time_point start_, last_draw_;
	long done_ = 0, total_ = 0;
	int last_decile_ = 0;
	bool drawn_ = false, finished_ = false;
};
}  // namespace codemark::app
