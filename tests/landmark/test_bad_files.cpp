// Bad values in ini and YAML files: rejected with the file and line named
// (MRPT's readers alone take "0.2x" as 0.2 and "abc" as 0).
#include <codemark/landmark/camera.h>
#include <codemark/landmark/geometry.h>
#include <codemark/landmark/text.h>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <unistd.h>

#include <exception>
#include <fstream>
#include <stdexcept>
#include <string>

using namespace codemark;

namespace
{
std::string writeTemp(const std::string& name, const std::string& text)
{
	const std::string p = ::testing::TempDir() + std::to_string(getpid()) + "_" + name;
	std::ofstream(p) << text;
	return p;
}

/** The message of the exception \a f throws ("" when it does not throw). */
template <typename F>
std::string errorOf(F&& f)
{
	try
	{
		f();
	}
	catch (const std::exception& e)
	{
		return e.what();
	}
	return {};
}

const char* kCamera =
	"[CAMERA_PARAMS]\nresolution = [640 480]\ncx = 319.5\ncy = 239.5\nfx = 800\nfy = 800\n"
	"dist = [0 0 0 0 0]\n";
}  // namespace

TEST(BadFiles, IniNumbersNameFileLineAndKey)
{
	const auto p = writeTemp("lm.ini", "# c\n[LANDMARK]\nouter_size_m = 0.2x\n");
	mrpt::config::CConfigFile cfg(p);
	LandmarkGeometry g;
	const std::string e = errorOf(
		[&]
		{
			try
			{
				g.loadFromConfigFile(cfg, "LANDMARK");
			}
			catch (const std::exception&)
			{
				rethrowNamingIniFile(p);
			}
		});
	EXPECT_NE(e.find(p + ":3: [LANDMARK] outer_size_m = '0.2x'"), std::string::npos) << e;
	EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

// A validator's "[SECTION] KEY: why" gets the file and the key's line; a
// message that already names another existing file is kept as it is; the
// kind (invalid value or I/O) is kept.
TEST(BadFiles, RethrowNamesTheLineOfAValidatorsKey)
{
	const auto p = writeTemp("opts.ini", "[a]\nk = 1\n\n[b]\n# c\nk = 2\nother = 3\n");
	const auto other = writeTemp("other.ini", "[pose]\n");
	const auto rethrown = [&](const std::exception_ptr& e)
	{
		try
		{
			try
			{
				std::rethrow_exception(e);
			}
			catch (const std::exception&)
			{
				rethrowNamingIniFile(p);
			}
		}
		catch (const std::invalid_argument& x)
		{
			return "invalid: " + std::string(x.what());
		}
		catch (const std::runtime_error& x)
		{
			return "runtime: " + std::string(x.what());
		}
		return std::string();
	};
	const auto thrown = [](auto e) { return std::make_exception_ptr(e); };
	EXPECT_EQ(
		rethrown(thrown(std::invalid_argument("[b] k: must be > 0"))),
		"invalid: " + p + ":6: [b] k: must be > 0");
	EXPECT_EQ(
		rethrown(thrown(std::invalid_argument("[B] Other = 'x' (expected y)"))),
		"invalid: " + p + ":7: [B] Other = 'x' (expected y)");
	// A key the file does not set (a default refused): the file alone.
	EXPECT_EQ(
		rethrown(thrown(std::runtime_error("[b] missing: must be > 0"))),
		"runtime: " + p + ": [b] missing: must be > 0");
	EXPECT_EQ(rethrown(thrown(std::runtime_error("no map"))), "runtime: " + p + ": no map");
	// Another file's own error: kept.
	EXPECT_EQ(
		rethrown(thrown(std::runtime_error(other + ":1: bad"))), "runtime: " + other + ":1: bad");
	EXPECT_EQ(
		rethrown(thrown(std::runtime_error(other + ": no [x]"))), "runtime: " + other + ": no [x]");
}

TEST(BadFiles, IniNumbersAcceptGoodValuesAndTrailingComments)
{
	const auto p =
		writeTemp("ok.ini", "[s]\na = 1.5 ; MRPT keeps this comment\nv = [1, 2 3]\nn = 7\n");
	mrpt::config::CConfigFile cfg(p);
	EXPECT_NO_THROW(requireIniNumbers(cfg, "s", {"a", "missing"}));
	EXPECT_NO_THROW(requireIniNumbers(cfg, "s", {"v"}, false, true));
	EXPECT_NO_THROW(requireIniNumbers(cfg, "s", {"n"}, true));
	EXPECT_THROW(requireIniNumbers(cfg, "s", {"a"}, true), IniValueError);
	EXPECT_THROW(requireIniNumbers(cfg, "s", {"v"}), IniValueError);
}

// MRPT's read_bool() takes anything but true/false/yes/no/number as false,
// and keeps a ';' comment in the value: "true ; note" reads false.
TEST(BadFiles, IniBooleansAreRefusedUnlessReadAsWritten)
{
	const auto p = writeTemp(
		"bools.ini",
		"[s]\na = TRUE\nb = no // MRPT drops this comment\nc = 0\nd = maybe\ne = true ; note\n");
	mrpt::config::CConfigFile cfg(p);
	EXPECT_NO_THROW(requireIniBooleans(cfg, "s", {"a", "b", "c", "missing"}));
	EXPECT_TRUE(cfg.read_bool("s", "a", false));
	EXPECT_FALSE(cfg.read_bool("s", "b", true));
	const std::string maybe = errorOf([&] { requireIniBooleans(cfg, "s", {"d"}, p); });
	EXPECT_NE(maybe.find(p + ":5: [s] d = 'maybe': not a boolean"), std::string::npos) << maybe;
	// The reason for refusing a commented boolean: MRPT would read it false.
	EXPECT_FALSE(cfg.read_bool("s", "e", true));
	const std::string note = errorOf([&] { requireIniBooleans(cfg, "s", {"e"}); });
	EXPECT_NE(note.find("comment"), std::string::npos) << note;
}

TEST(BadFiles, CameraIniBadNumberMissingKeyNan)
{
	const std::string good = kCamera;
	EXPECT_NO_THROW(CameraModel::load(writeTemp("good.ini", good)));
	const auto bad =
		writeTemp("bad.ini", std::string(kCamera).replace(good.find("fx = 800"), 8, "fx = 8o0"));
	EXPECT_NE(
		errorOf([&] { CameraModel::load(bad); }).find(bad + ":5: [CAMERA_PARAMS] fx = '8o0'"),
		std::string::npos);
	const auto nan =
		writeTemp("nan.ini", std::string(kCamera).replace(good.find("fy = 800"), 8, "fy = nan"));
	EXPECT_NE(errorOf([&] { CameraModel::load(nan); }).find(nan + ":6:"), std::string::npos);
	const auto res =
		writeTemp("res.ini", std::string(kCamera).replace(good.find("[640 480]"), 9, "[640 x]"));
	EXPECT_NE(errorOf([&] { CameraModel::load(res); }).find("resolution"), std::string::npos);
	const auto missing =
		writeTemp("missing.ini", std::string(kCamera).replace(good.find("fx = 800\n"), 9, ""));
	EXPECT_NE(errorOf([&] { CameraModel::load(missing); }).find("'fx'"), std::string::npos);
}

TEST(BadFiles, RosYamlBadNumberAndSyntaxError)
{
	const std::string ros =
		"image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
		"  data: [800, 0, 319.5, 0, 800, 239.5, 0, 0, 1]\ndistortion_model: plumb_bob\n"
		"distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n";
	EXPECT_NO_THROW(CameraModel::load(writeTemp("good.yaml", ros)));
	const auto bad =
		writeTemp("bad.yaml", std::string(ros).replace(ros.find("800, 0, 319.5"), 3, "8x0"));
	EXPECT_NE(errorOf([&] { CameraModel::load(bad); }).find("'8x0'"), std::string::npos);
	const auto shortm =
		writeTemp("short.yaml", std::string(ros).replace(ros.find(", 0, 0, 1]"), 10, "]"));
	EXPECT_NE(errorOf([&] { CameraModel::load(shortm); }).find("9 numbers"), std::string::npos);
	// A syntax error: libfyaml's diagnostic becomes the one-line message, with the line.
	const auto garbage = writeTemp("garbage.yaml", "image_width: [640\n: : :\n");
	const std::string e = errorOf([&] { CameraModel::load(garbage); });
	EXPECT_NE(e.find(garbage + ":2:"), std::string::npos) << e;
	EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(BadFiles, YamlDirectivesTabsAndControlCharactersAreRefused)
{
	// libfyaml 0.8 loops forever on some directives (found by fuzz_camera),
	// also after a lone '\r' line break; camera files never hold any.
	const auto directive = writeTemp("directive.yaml", "image_width: 320\nx: 1 \r\r%ta: [8\n");
	const std::string e = errorOf([&] { CameraModel::load(directive); });
	EXPECT_NE(e.find(directive + ":4: YAML directives"), std::string::npos) << e;
	const auto control = writeTemp("control.yaml", std::string("image_width: 3\x01\n", 16));
	EXPECT_NE(
		errorOf([&] { CameraModel::load(control); }).find("control character"), std::string::npos);
	// libfyaml 0.8 segfaults reporting this one (fuzz_camera): tabs in a
	// malformed plain scalar.
	const std::string tabs(40, '\t');
	const auto tabbed = writeTemp(
		"tabs.yaml", "image_width: 640\nimage_height: 480\ncam" + tabs + "m" + tabs + "[-0am" +
						 tabs + ".ols: 5\n  " + tabs + "en [-0am" + tabs +
						 ".ols: 5\n  data:0, 0, 0]\n");
	const std::string t = errorOf([&] { CameraModel::load(tabbed); });
	EXPECT_NE(t.find(tabbed + ":3: tab character"), std::string::npos) << t;
}

TEST(BadFiles, OpenCvYamlThatHangsOpenCvsReaderIsRefused)
{
	// OpenCV 4.6's own YAML reader loops forever on these (found by
	// fuzz_camera): a document start with text after it and a later '---';
	// a line indented between an enclosing block and the block before it.
	// The loader reads OpenCV's format with the guarded YAML reader of the
	// ROS format: each is refused, with the file named.
	const auto doc = writeTemp("doc_start.yaml", "%YAML:1.0\n---a:0\n1---\n");
	const std::string e = errorOf([&] { CameraModel::load(doc); });
	EXPECT_NE(e.find(doc + ": expected a YAML map of camera keys"), std::string::npos) << e;
	const auto dedent =
		writeTemp("dedent_cv.yaml", "%YAML:1.0\n   rows: 0\n   cols: 5\n tor-ion_model\n");
	const std::string d = errorOf([&] { CameraModel::load(dedent); });
	EXPECT_NE(d.find(dedent + ": missing required key 'image_width'"), std::string::npos) << d;
	const auto control =
		writeTemp("control_cv.yaml", std::string("%YAML:1.0\n---\nimage_width: 6\0\n", 30));
	const std::string c = errorOf([&] { CameraModel::load(control); });
	EXPECT_NE(c.find(control + ":3: control character"), std::string::npos) << c;
	// A matrix whose rows x cols disagrees with its data.
	const auto dims = writeTemp(
		"dims_cv.yaml",
		"%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
		"   rows: 30000\n   cols: 30000\n   dt: d\n   data: [ 1., 0., 1., 0., 1., 1., 0., 0., 1. "
		"]\n");
	const std::string m = errorOf([&] { CameraModel::load(dims); });
	EXPECT_NE(m.find(dims + ": 'camera_matrix' has rows x cols unlike its 9"), std::string::npos)
		<< m;
}
