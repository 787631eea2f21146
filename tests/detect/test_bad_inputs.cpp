// Bad inputs (the bad-input sweep, for the detector): the entry point gives a
// clear error or nothing, never a crash or a hang; codemark-detect prints one
// JSON error line per bad input and exits non-zero at the end.
#include <codemark/detect/detector.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

using namespace codemark;
using namespace codemark::detect;
namespace fs = std::filesystem;

namespace
{
DetectionResult run(const cv::Mat& img)
{
	return codemark::detect::detect(
		img, CameraModel::paperDefault(), LandmarkGeometry(), DetectorOptions());
}

/** The detector throws std::invalid_argument with a message naming the
 * expected type, or returns nothing. */
void expectErrorOrNothing(const cv::Mat& img, const std::string& what)
{
	try
	{
		const auto r = run(img);
		EXPECT_TRUE(r.landmarks.empty()) << what;
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("CV_8UC3"), std::string::npos)
			<< what << ": " << e.what();
	}
}
}  // namespace

TEST(BadInputs, DetectorGivesAClearErrorOrNothing)
{
	expectErrorOrNothing(cv::Mat(), "0x0");
	expectErrorOrNothing(cv::Mat(0, 0, CV_8UC3), "0x0 colour");
	expectErrorOrNothing(cv::Mat(1, 1, CV_8UC3, cv::Scalar(0, 255, 0)), "1x1");
	expectErrorOrNothing(cv::Mat(2, 3, CV_8UC3, cv::Scalar(0, 255, 0)), "2x3");
	expectErrorOrNothing(cv::Mat(480, 1, CV_8UC3, cv::Scalar(0, 255, 0)), "one column");
	expectErrorOrNothing(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), "grey");
	expectErrorOrNothing(cv::Mat(480, 640, CV_16UC3, cv::Scalar(0, 65535, 0)), "16-bit");
	expectErrorOrNothing(cv::Mat(480, 640, CV_8UC4, cv::Scalar(0, 255, 0, 255)), "4 channels");
	expectErrorOrNothing(cv::Mat(480, 640, CV_32FC3, cv::Scalar(0, 1, 0)), "float");
	// Non-colour types are refused with an exception, not read as BGR.
	EXPECT_THROW(run(cv::Mat(480, 640, CV_8UC1)), std::invalid_argument);
	EXPECT_THROW(run(cv::Mat(480, 640, CV_8UC4)), std::invalid_argument);
	EXPECT_THROW(run(cv::Mat(480, 640, CV_16UC3)), std::invalid_argument);
}

TEST(BadInputs, HugeFrameIsProcessed)
{
	// 8000 x 8000 (192 MB): all green, so every stage sees one huge
	// component, plus a green square with a black frame at a corner.
	cv::Mat img(8000, 8000, CV_8UC3, cv::Scalar(0, 255, 0));
	cv::rectangle(img, cv::Rect(100, 100, 500, 500), cv::Scalar(20, 20, 20), cv::FILLED);
	cv::rectangle(img, cv::Rect(150, 150, 400, 400), cv::Scalar(0, 255, 0), cv::FILLED);
	const auto r = run(img);
	EXPECT_TRUE(r.landmarks.empty());
}

TEST(BadInputs, AppPrintsOneErrorLinePerBadInputAndFailsAtTheEnd)
{
	const fs::path dir =
		fs::temp_directory_path() / ("codemark_detect_bad_" + std::to_string(getpid()));
	fs::remove_all(dir);
	fs::create_directories(dir);
	const cv::Mat green(480, 640, CV_8UC3, cv::Scalar(0, 255, 0));
	ASSERT_TRUE(cv::imwrite((dir / "good.png").string(), green));
	ASSERT_TRUE(
		cv::imwrite((dir / "tiny.png").string(), cv::Mat(1, 1, CV_8UC3, cv::Scalar(0, 255, 0))));
	ASSERT_TRUE(
		cv::imwrite((dir / "grey.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(128))));
	ASSERT_TRUE(cv::imwrite(
		(dir / "deep.png").string(), cv::Mat(480, 640, CV_16UC3, cv::Scalar(0, 65535, 0))));
	cv::Mat bgra;
	cv::cvtColor(green, bgra, cv::COLOR_BGR2BGRA);
	ASSERT_TRUE(cv::imwrite((dir / "alpha.png").string(), bgra));
	std::ofstream(dir / "text.png") << "not an image\n";
	std::ofstream(dir / "empty.jpg");
	const std::string out = (dir / "out.jsonl").string();
	std::ostringstream cmd;
	cmd << "'" << CODEMARK_DETECT_APP << "'";
	for (const char* f :
		 {"good.png", "text.png", "tiny.png", "grey.png", "missing.png", "deep.png", "alpha.png",
		  "empty.jpg"})
		cmd << " '" << (dir / f).string() << "'";
	cmd << " > '" << out << "' 2> /dev/null";
	const int rc = std::system(cmd.str().c_str());
	ASSERT_TRUE(WIFEXITED(rc)) << "codemark-detect crashed";
	EXPECT_NE(WEXITSTATUS(rc), 0);
	std::ifstream in(out);
	std::string line;
	std::vector<std::string> lines;
	while (std::getline(in, line)) lines.push_back(line);
	// One line per input, in order; the unreadable ones are errors, and so
	// are images the camera (640x480 colour) cannot have taken: 1x1, grey,
	// 16-bit. A 4-channel image of the camera's size is read as colour.
	ASSERT_EQ(lines.size(), 8u);
	const bool error[8] = {false, true, true, true, true, true, false, true};
	for (size_t i = 0; i < lines.size(); ++i)
	{
		EXPECT_EQ(lines[i].find("\"error\"") != std::string::npos, error[i]) << lines[i];
		EXPECT_EQ(lines[i].rfind("{", 0), 0u) << lines[i];
		if (!error[i])
		{
			EXPECT_NE(lines[i].find("\"detections\": []"), std::string::npos) << lines[i];
		}
	}
	fs::remove_all(dir);
}
