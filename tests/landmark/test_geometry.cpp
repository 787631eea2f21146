#include <fstream>
#include <sstream>
#include <codemark/landmark/geometry.h>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

using namespace codemark;

TEST(Geometry, ReferencePointsAsSeenFromTheFront)
{
	const LandmarkGeometry g;
	const auto p = g.referencePoints();
	// Frame L: X_L out of the wall, Y_L to the observer's right, Z_L up.
	for (const auto& q : p) EXPECT_DOUBLE_EQ(q.x(), 0.0);
	EXPECT_DOUBLE_EQ(p[0].y(), -0.08);	// top-left
	EXPECT_DOUBLE_EQ(p[0].z(), 0.08);
	EXPECT_DOUBLE_EQ(p[1].y(), 0.08);  // top-right
	EXPECT_DOUBLE_EQ(p[2].z(), -0.08);	// bottom-right
	EXPECT_DOUBLE_EQ(p[3].y(), -0.08);	// bottom-left
	EXPECT_DOUBLE_EQ(p[3].z(), -0.08);
	// Y_L = Z_L x X_L.
	EXPECT_TRUE(Eigen::Vector3d::UnitZ()
					.cross(Eigen::Vector3d::UnitX())
					.isApprox(Eigen::Vector3d::UnitY()));
}

TEST(Geometry, ScaleKeepsProportions)
{
	const auto g = LandmarkGeometry::scaled(1.5);
	EXPECT_DOUBLE_EQ(g.outer_size_m, 0.3);
	EXPECT_DOUBLE_EQ(g.inner_size_m, 0.24);
	EXPECT_DOUBLE_EQ(g.cell_size_m, 0.045);
	EXPECT_DOUBLE_EQ(g.cellCentreFace(0, 0).x(), -0.045);
	EXPECT_DOUBLE_EQ(g.cellCentreFace(0, 0).y(), 0.045);
	EXPECT_THROW(LandmarkGeometry::scaled(0), std::invalid_argument);
	EXPECT_THROW(LandmarkGeometry::scaled(-1), std::invalid_argument);
}

TEST(Geometry, IniRoundTripAndValidation)
{
	mrpt::config::CConfigFileMemory cfg;
	LandmarkGeometry g = LandmarkGeometry::scaled(2.0);
	g.saveToConfigFile(cfg, "LANDMARK");
	LandmarkGeometry back;
	back.loadFromConfigFile(cfg, "LANDMARK");
	EXPECT_DOUBLE_EQ(back.inner_size_m, 0.32);
	EXPECT_DOUBLE_EQ(back.outer_size_m, 0.4);

	mrpt::config::CConfigFileMemory bad;
	bad.write("LANDMARK", "inner_size_m", 0.3);	 // larger than the outer edge
	LandmarkGeometry b;
	EXPECT_THROW(b.loadFromConfigFile(bad, "LANDMARK"), std::invalid_argument);
}

TEST(Geometry, ShippedIniLoads)
{
	mrpt::config::CConfigFileMemory cfg;
	std::ifstream f(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/landmark.ini");
	ASSERT_TRUE(f.good());
	std::stringstream ss;
	ss << f.rdbuf();
	cfg.setContent(ss.str());
	LandmarkGeometry g;
	g.loadFromConfigFile(cfg, "LANDMARK");
	EXPECT_DOUBLE_EQ(g.innerHalf(), 0.08);
	EXPECT_DOUBLE_EQ(g.outer_size_m, 0.2);
	// The same file with its scale doubled: every size doubles.
	std::string text = ss.str();
	const auto pos = text.find("scale        = 1.0");
	ASSERT_NE(pos, std::string::npos);
	text.replace(pos, 18, "scale = 2");
	cfg.setContent(text);
	LandmarkGeometry g2;
	g2.loadFromConfigFile(cfg, "LANDMARK");
	EXPECT_DOUBLE_EQ(g2.innerHalf(), 0.16);
	EXPECT_DOUBLE_EQ(g2.cell_size_m, 0.06);
}
