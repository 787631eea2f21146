// Ground-truth path files (docs/spec.md section 6, both forms).
#include <codemark/eval/ground_truth.h>
#include <codemark/landmark/text.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace codemark::eval
{
GroundTruth GroundTruth::load(const std::string& path)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error(path + ": cannot open ground-truth file");
	GroundTruth gt;
	std::string line;
	int lineno = 0;
	int columns = 0;
	while (std::getline(in, line))
	{
		++lineno;
		const auto first = line.find_first_not_of(" \t\r");
		if (first == std::string::npos || line[first] == '#' || line[first] == '%') continue;
		const std::vector<double> v = parseNumberRow(line, path, lineno, "#%");
		const int n = static_cast<int>(v.size());
		if (columns == 0)
		{
			if (n != 4 && n != 6)
				throw std::runtime_error(
					path + ":" + std::to_string(lineno) + ": " + std::to_string(n) +
					" columns; expected 4 (timestamp x y yaw) or 6 (MRPT path: x y z yaw pitch "
					"roll)");
			columns = n;
			gt.form_ = n == 4 ? Form::Timestamped : Form::MrptPath;
		}
		else if (n != columns)
			throw std::runtime_error(
				path + ":" + std::to_string(lineno) + ": " + std::to_string(n) +
				" columns, expected " + std::to_string(columns) + " as in the first row");
		if (columns == 4)
		{
			if (!gt.times_.empty() && v[0] < gt.times_.back())
				throw std::runtime_error(
					path + ":" + std::to_string(lineno) + ": timestamps not ascending");
			gt.times_.push_back(v[0]);
			gt.poses_.emplace_back(v[1], v[2], v[3]);
		}
		else
			gt.poses_.emplace_back(v[0], v[1], v[3]);
	}
	if (gt.poses_.empty()) throw std::runtime_error(path + ": no ground-truth rows");
	return gt;
}

std::optional<mrpt::poses::CPose2D> GroundTruth::poseAt(
	long index, double t, double tol, long actions) const
{
	if (form_ == Form::MrptPath)
	{
		const long row = actions >= 0 ? actions : index + 1;
		if (row < 0 || row >= static_cast<long>(poses_.size())) return std::nullopt;
		return poses_[row];
	}
	const auto it = std::lower_bound(times_.begin(), times_.end(), t);
	std::optional<std::size_t> best;
	double best_dt = tol;
	for (auto c : {it, it == times_.begin() ? it : it - 1})
	{
		if (c == times_.end()) continue;
		const double dt = std::abs(*c - t);
		if (dt <= best_dt)
		{
			best_dt = dt;
			best = static_cast<std::size_t>(c - times_.begin());
		}
	}
	if (!best) return std::nullopt;
	return poses_[*best];
}

}  // namespace codemark::eval
