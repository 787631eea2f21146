#pragma once
/** \file preset.h
 * `--preset NAME` of the apps that render: the camera preset applied first,
 * so that the stage keys of an options file given with it override it (as a
 * `preset` key inside the file does).
 */
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace codemark::app
{
/** The help text of `--preset`: the names and what they are. */
inline std::string presetHelp()
{
	std::string names;
	for (const auto& n : sim::RenderOptions::presetNames()) names += (names.empty() ? "" : "|") + n;
	return "camera preset (" + names +
		   "): the camera pipeline's stages as a named parameter set (docs/camera-pipeline.md); "
		   "stage keys of the render options override it";
}

/** The ini \a file (empty: none) in memory, with `preset = NAME` set in
 * [\a section] when \a preset is not empty (it replaces a preset key of the
 * file). Throws std::runtime_error naming an unreadable file and
 * std::invalid_argument for an unknown preset. */
inline mrpt::config::CConfigFileMemory iniWithPreset(
	const std::string& file, const std::string& section, const std::string& preset)
{
	mrpt::config::CConfigFileMemory mem;
	if (!file.empty())
	{
		std::ifstream in(file);
		if (!in.good()) throw std::runtime_error(file + ": cannot open options file");
		std::ostringstream text;
		text << in.rdbuf();
		mem.setContent(text.str());
	}
	if (!preset.empty())
	{
		(void)sim::RenderOptions::presetKeys(preset);  // an unknown name throws here
		mem.write(section, "preset", preset);
	}
	return mem;
}
}  // namespace codemark::app
