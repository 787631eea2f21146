#pragma once
/** \file calibration.h
 * The `--calibration` argument every measuring tool takes: a calibration
 * file of C_P (docs/calibration.md) or the name of a shipped one. */
#include <codemark/pipeline/pipeline.h>
#include <codemark/pose/calibration.h>
#include <tclap/CmdLine.h>

#include <string>

namespace codemark::app
{
/** The shipped calibrations' names, comma-separated. */
inline std::string shippedNames()
{
	std::string names;
	for (const auto& n : pose::shippedCalibrationNames()) names += (names.empty() ? "" : ", ") + n;
	return names;
}

/** The --calibration help text, naming the shipped calibrations. */
inline std::string calibrationHelp()
{
	const std::string names = shippedNames();
	return "C_P's noise model: a calibration file (docs/calibration.md; "
		   "codemark-bench-pose-calib --out writes one) or the name of a shipped one (" +
		   names + "). Default: " + pipeline::kDefaultCalibration +
		   ". A [pose] section of a config overrides its keys.";
}

/** The --calibration argument, added to \a cmd. */
inline TCLAP::ValueArg<std::string> calibrationArg(TCLAP::CmdLine& cmd)
{
	return TCLAP::ValueArg<std::string>(
		"", "calibration", calibrationHelp(), false, pipeline::kDefaultCalibration, "FILE|NAME",
		cmd);
}
}  // namespace codemark::app
