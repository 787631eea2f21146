#include <codemark/landmark/truth.h>
#include <gtest/gtest.h>

using namespace codemark;
using mrpt::poses::CPose3D;

namespace
{
// A level camera (optical axis horizontal) at (x, y, z) in frame L whose
// optical axis has heading \a heading in L: the robot convention pose
// (x forward) composed with MRPT's optical-frame rotation.
CPose3D levelCamera(double x, double y, double z, double heading)
{
	return CPose3D(x, y, z, heading, 0, 0) + CPose3D(0, 0, 0, -M_PI / 2, 0, -M_PI / 2);
}
}  // namespace

TEST(Truth, SquarelyInFront)
{
	const auto t = sightingTruth(levelCamera(2.0, 0, 0.3, M_PI));
	EXPECT_NEAR(t.L[0], 2.0, 1e-12);
	EXPECT_NEAR(t.L[1], 0.0, 1e-12);
	EXPECT_NEAR(t.L[2], 0.0, 1e-12);
	EXPECT_NEAR(std::abs(t.pose_in_landmark[2]), M_PI, 1e-12);
}

TEST(Truth, SignsFollowTheSpec)
{
	// Camera on the landmark's +Y side (the observer's right), looking at the
	// landmark centre: the landmark is dead ahead, phi1 = 0; the optical axis
	// is rotated clockwise from the inward normal, phi2 < 0.
	const double a = 0.4;
	auto t = sightingTruth(levelCamera(2 * std::cos(a), 2 * std::sin(a), 0, M_PI + a));
	EXPECT_NEAR(t.L[1], 0.0, 1e-12);
	EXPECT_NEAR(t.L[2], a, 1e-12);
	// Turning the camera to the right (clockwise) puts the landmark on the left of the image: phi1
	// > 0.
	t = sightingTruth(levelCamera(2, 0, 0, M_PI - 0.1));
	EXPECT_NEAR(t.L[1], 0.1, 1e-12);
	EXPECT_NEAR(t.L[2], -0.1, 1e-12);
	// x = l2 cos(phi1 + phi2), y = l2 sin(phi1 + phi2), theta = pi + phi2.
	t = sightingTruth(levelCamera(1.7, -0.6, 0.2, 2.9));
	EXPECT_NEAR(t.pose_in_landmark[0], t.L[0] * std::cos(t.L[1] + t.L[2]), 1e-12);
	EXPECT_NEAR(t.pose_in_landmark[1], t.L[0] * std::sin(t.L[1] + t.L[2]), 1e-12);
	EXPECT_NEAR(wrapToPi(t.pose_in_landmark[2] - M_PI - t.L[2]), 0.0, 1e-12);
}

TEST(Truth, WrapToPi)
{
	EXPECT_DOUBLE_EQ(wrapToPi(M_PI), M_PI);
	EXPECT_DOUBLE_EQ(wrapToPi(-M_PI), M_PI);
	EXPECT_NEAR(wrapToPi(3 * M_PI + 0.1), -M_PI + 0.1, 1e-12);
	EXPECT_NEAR(wrapToPi(-0.2), -0.2, 1e-15);
}
