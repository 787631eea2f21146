#pragma once
/** \file povray_args.h
 * `--renderer own|povray` and the POV-Ray renderer's options of the apps
 * that render (codemark-render, codemark-simul); see docs/povray.md.
 */
#include <codemark/sim/povray.h>
#include <codemark/sim/render.h>
#include <mrpt/config/CConfigFile.h>
#include <tclap/CmdLine.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace codemark::app
{
/** The renderer choice and the POV-Ray options, registered with a TCLAP
 * command line. */
struct PovrayArgs
{
	TCLAP::ValueArg<std::string> renderer;
	TCLAP::ValueArg<std::string> ini;
	TCLAP::ValueArg<std::string> light;
	TCLAP::ValueArg<std::string> light_type;
	TCLAP::ValueArg<double> light_gradient;
	TCLAP::ValueArg<std::string> wall;
	TCLAP::ValueArg<std::string> floor;
	TCLAP::ValueArg<uint64_t> texture_seed;
	TCLAP::ValueArg<int> threads;

	explicit PovrayArgs(TCLAP::CmdLine& cmd)
		: renderer(
			  "", "renderer",
			  "own (default): the project's exact-coverage renderer; povray: the independent "
			  "POV-Ray 3.7 ray tracer (docs/povray.md; needs the povray program)",
			  false, "own", "own|povray", cmd),
		  ini("", "povray-ini",
			  "POV-Ray renderer options file, section [povray] (keys of "
			  "codemark::sim::PovrayOptions); the --light, --light-type, --light-gradient, --wall, "
			  "--floor, --texture-seed and --povray-threads flags override it",
			  false, "", "INI", cmd),
		  light(
			  "", "light", "POV-Ray: light level (default normal)", false, "", "dim|normal|bright",
			  cmd),
		  light_type(
			  "", "light-type",
			  "POV-Ray: point or area lamps, or flat ambient light (default point)", false, "",
			  "point|area|ambient", cmd),
		  light_gradient(
			  "", "light-gradient",
			  "POV-Ray: relative change of the lamp's light across the sheet, left to right "
			  "(-0.45..0.45, default 0)",
			  false, 0.0, "G", cmd),
		  wall(
			  "", "wall", "POV-Ray: wall paint (default auto: plain for a Flat background)", false,
			  "", "auto|plain|plaster|brick", cmd),
		  floor(
			  "", "floor", "POV-Ray: floor cover (default tiles)", false, "", "plain|tiles|wood",
			  cmd),
		  texture_seed(
			  "", "texture-seed", "POV-Ray: seed of the wall and floor patterns (default 1)", false,
			  1, "N", cmd),
		  threads(
			  "", "povray-threads", "POV-Ray: threads per render (default 1)", false, 1, "N", cmd)
	{
	}

	/** True with --renderer povray; throws std::invalid_argument naming
	 * --renderer on another name than own or povray. */
	bool povray() const
	{
		const std::string& r = renderer.getValue();
		if (r != "own" && r != "povray")
			throw std::invalid_argument("--renderer must be 'own' or 'povray', got '" + r + "'");
		return r == "povray";
	}

	/** The POV-Ray options: the file's, then the flags given. */
	sim::PovrayOptions options() const
	{
		sim::PovrayOptions o;
		if (ini.isSet())
		{
			if (!std::ifstream(ini.getValue()).good())
				throw std::runtime_error(ini.getValue() + ": cannot open POV-Ray options file");
			mrpt::config::CConfigFile cfg(ini.getValue());
			o.loadFromConfigFile(cfg, "povray");
		}
		if (light.isSet()) o.light = sim::lightLevelFromName(light.getValue(), "--light");
		if (light_type.isSet())
			o.light_type = sim::lightTypeFromName(light_type.getValue(), "--light-type");
		if (light_gradient.isSet()) o.light_gradient = light_gradient.getValue();
		if (wall.isSet()) o.wall = sim::wallTextureFromName(wall.getValue(), "--wall");
		if (floor.isSet()) o.floor = sim::floorTextureFromName(floor.getValue(), "--floor");
		if (texture_seed.isSet()) o.texture_seed = texture_seed.getValue();
		if (threads.isSet()) o.threads = threads.getValue();
		o.validate();
		return o;
	}

	/** The renderer chosen: sim::render or the POV-Ray renderer. */
	sim::Renderer make() const
	{
		if (!povray()) return sim::Renderer(sim::render);
		return sim::povrayRenderer(options());
	}

	/** With --renderer povray: copies the linear 16-bit render of a frame
	 * (from the cache) to \a path. */
	void saveLinear(
		const sim::Scene& scene, const sim::RenderOptions& o, uint64_t seed,
		const std::string& path) const
	{
		if (!povray()) return;
		std::filesystem::copy_file(
			sim::povrayCachedRender(scene, o, options(), seed), path,
			std::filesystem::copy_options::overwrite_existing);
	}
};
}  // namespace codemark::app
