// The coded-landmark map (CCodedLandmarksMap) and the particle filter.
#include <codemark/eval/localization.h>
#include <codemark/filters/particle_filter.h>
#include <codemark/mrpt/CCodedLandmarksMap.h>
#include <gtest/gtest.h>

#include "../common/serialization_io.h"
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/io/vector_loadsave.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/filesystem.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "synthetic.h"

using codemark::CCodedLandmarksMap;
using codemark::CObservationCodedLandmarks;
using mrpt::poses::CPose2D;
using mrpt::poses::CPose3D;
namespace pft = codemark::pftest;

namespace
{
double loglik(const CCodedLandmarksMap& m, const mrpt::obs::CObservation& o, const CPose2D& p)
{
	return m.computeObservationLikelihood(o, CPose3D(p));
}

/** The shipped pf.ini with a fixed seed. */
mrpt::config::CConfigFileMemory shippedConfig(int seed)
{
	mrpt::config::CConfigFileMemory cfg(
		mrpt::io::file_get_contents(std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/pf.ini"));
	cfg.write("ParticleFilter", "random_seed", seed);
	return cfg;
}

double positionError(const codemark::filters::PoseEstimate& e, const CPose2D& truth)
{
	return std::hypot(e.mean.x() - truth.x(), e.mean.y() - truth.y());
}

/** A pose from which the room's landmarks are in view. */
const CPose2D kPose(2.2, 1.7, 0.3);

constexpr double kLambda = 500;	 // focal length of the cameras below [px]

/** \a o's sightings as the closed form measures them: P from each one's L
 * (a level camera of focal length kLambda, 640 x 480), C_P = sigma_px^2 I. */
void measureInPrimary(
	CObservationCodedLandmarks& o, const codemark::LandmarkMap& map, double sigma_px = 0.15)
{
	o.camera.ncols = 640;
	o.camera.nrows = 480;
	o.camera.fx(kLambda);
	o.camera.fy(kLambda);
	o.camera.cx(320);
	o.camera.cy(240);
	for (auto& s : o.sightings)
	{
		s.method = codemark::pose::PoseMethod::ClosedForm;
		s.P = codemark::pose::primaryFromLandmark(
			s.L, kLambda, map.find(s.id)->geometry().innerHalf());
		s.C_P = Eigen::Matrix4d::Identity() * sigma_px * sigma_px;
	}
}
}  // namespace

// ------------------------------------------------------------------- map
TEST(CodedLandmarksMap, PredictedLMatchesTheTruth)
{
	const auto map = pft::room();
	for (int k = 0; k < 80; k += 7)
	{
		const CPose2D p = pft::circlePose(k);
		const auto o = pft::observe(p, map);
		ASSERT_FALSE(o->sightings.empty()) << "step " << k;
		double cx, cy, cc, cs;
		ASSERT_TRUE(CCodedLandmarksMap::cameraInWorld(
			p.x(), p.y(), std::cos(p.phi()), std::sin(p.phi()), o->cameraPose, cx, cy, cc, cs));
		for (const auto& s : o->sightings)
		{
			const auto* lm = map.find(s.id);
			const Eigen::Vector3d Lp = CCodedLandmarksMap::predictL(
				cx, cy, cc, cs, lm->x_m, lm->y_m, std::cos(lm->yaw_rad), std::sin(lm->yaw_rad));
			EXPECT_NEAR(Lp[0], s.L[0], 1e-9);
			EXPECT_NEAR(Lp[1], s.L[1], 1e-9);
			EXPECT_NEAR(Lp[2], s.L[2], 1e-9);
		}
	}
}

TEST(CodedLandmarksMap, SerializationRoundTrip)
{
	CCodedLandmarksMap m(pft::room());
	m.likelihoodOptions.outlier_probability = 0.125;
	m.likelihoodOptions.sigma_scale = 2.5;
	m.likelihoodOptions.max_range_m = 12;
	auto lms = m.landmarks();
	lms.landmarks[3].scale = 0.5;
	m.setLandmarks(lms);
	for (const CCodedLandmarksMap& in : {CCodedLandmarksMap(), m})
	{
		const auto obj = codemark::test::fromBytes(codemark::test::toBytes(in));
		const auto out = std::dynamic_pointer_cast<CCodedLandmarksMap>(obj);
		ASSERT_TRUE(out);
		ASSERT_EQ(out->landmarks().landmarks.size(), in.landmarks().landmarks.size());
		for (size_t i = 0; i < in.landmarks().landmarks.size(); ++i)
		{
			const auto &a = in.landmarks().landmarks[i], &b = out->landmarks().landmarks[i];
			EXPECT_EQ(a.id, b.id);
			EXPECT_EQ(a.x_m, b.x_m);
			EXPECT_EQ(a.y_m, b.y_m);
			EXPECT_EQ(a.z_m, b.z_m);
			EXPECT_EQ(a.yaw_rad, b.yaw_rad);
			EXPECT_EQ(a.scale, b.scale);
			EXPECT_EQ(out->find(a.id), &b);
		}
		EXPECT_EQ(
			out->likelihoodOptions.outlier_probability, in.likelihoodOptions.outlier_probability);
		EXPECT_EQ(out->likelihoodOptions.sigma_scale, in.likelihoodOptions.sigma_scale);
		EXPECT_EQ(out->likelihoodOptions.max_range_m, in.likelihoodOptions.max_range_m);
	}
}

TEST(CodedLandmarksMap, UnknownVersionThrows)
{
	auto b = codemark::test::toBytes(CCodedLandmarksMap(pft::room()));
	// MRPT's object header: 0x80|len, class name, version byte.
	const std::string name = "codemark::CCodedLandmarksMap";
	const auto it = std::search(b.begin(), b.end(), name.begin(), name.end());
	ASSERT_NE(it, b.end());
	EXPECT_NO_THROW(codemark::test::fromBytes(b));
	*(it + static_cast<std::ptrdiff_t>(name.size())) = 99;
	EXPECT_ANY_THROW(codemark::test::fromBytes(b));
}

TEST(CodedLandmarksMap, BuiltFromIniByMultiMetricMap)
{
	const std::string file = mrpt::system::getTempFileName() + "_map.txt";
	pft::room().save(file);
	mrpt::config::CConfigFileMemory cfg;
	cfg.write("MetricMap", "codedLandmarksMap_count", 1);
	cfg.write("MetricMap_codedLandmarksMap_00_creationOpts", "map_file", file);
	cfg.write("MetricMap_codedLandmarksMap_00_likelihoodOpts", "outlier_probability", 0.2);
	mrpt::maps::TSetOfMetricMapInitializers inits;
	inits.loadFromConfigFile(cfg, "MetricMap");
	ASSERT_EQ(inits.size(), 1u);
	mrpt::maps::CMultiMetricMap mm;
	mm.setListOfMaps(inits);
	const auto m = mm.mapByClass<CCodedLandmarksMap>();
	ASSERT_TRUE(m);
	EXPECT_EQ(m->landmarks().landmarks.size(), pft::room().landmarks.size());
	ASSERT_TRUE(m->find(7));
	EXPECT_DOUBLE_EQ(m->find(7)->x_m, pft::room().find(7)->x_m);
	EXPECT_DOUBLE_EQ(m->likelihoodOptions.outlier_probability, 0.2);
	// The multi-map sums our likelihood: it must peak at the truth too.
	const auto o = pft::observe(kPose, pft::room());
	EXPECT_GT(
		mm.computeObservationLikelihood(*o, CPose3D(kPose)),
		mm.computeObservationLikelihood(
			*o, CPose3D(CPose2D(kPose.x() + 0.1, kPose.y(), kPose.phi()))));
	std::remove(file.c_str());

	// A missing landmark file is an error, not an empty map.
	cfg.write("MetricMap_codedLandmarksMap_00_creationOpts", "map_file", file + ".missing");
	inits.loadFromConfigFile(cfg, "MetricMap");
	mrpt::maps::CMultiMetricMap mm2;
	EXPECT_ANY_THROW(mm2.setListOfMaps(inits));
}

TEST(CodedLandmarksMap, LikelihoodPeaksAtTheTruePose)
{
	const CCodedLandmarksMap m(pft::room());
	const auto o = pft::observe(kPose, m.landmarks());
	ASSERT_GE(o->sightings.size(), 2u);
	const double at_truth = loglik(m, *o, kPose);
	EXPECT_TRUE(std::isfinite(at_truth));
	for (const auto& d :
		 {CPose2D(0.03, 0, 0), CPose2D(0, -0.03, 0), CPose2D(0, 0, 0.02),
		  CPose2D(-0.1, 0.05, -0.05), CPose2D(1, 1, 1)})
		EXPECT_GT(at_truth, loglik(m, *o, kPose + d)) << d;
}

TEST(CodedLandmarksMap, OutliersStayFiniteAndBounded)
{
	CCodedLandmarksMap m(pft::room());
	auto o = pft::observe(kPose, m.landmarks());
	const double clean = loglik(m, *o, kPose);
	auto bad = o->sightings.front();
	bad.L = {7.5, 0.9, -2.5};  // nothing like the truth
	o->sightings.push_back(bad);
	const double with_outlier = loglik(m, *o, kPose);
	ASSERT_TRUE(std::isfinite(with_outlier));
	// The mixture's floor: log(p U), U = 1 / (max_range (2 pi)^2).
	const auto& lo = m.likelihoodOptions;
	const double floor =
		std::log(lo.outlier_probability) - std::log(lo.max_range_m * 4 * M_PI * M_PI);
	EXPECT_GE(with_outlier - clean, floor - 1e-9);
	EXPECT_LT(with_outlier - clean, floor + 0.1);
	// Without the uniform, the same outlier costs far more.
	m.likelihoodOptions.outlier_probability = 0;
	EXPECT_LT(
		loglik(m, *o, kPose) - loglik(m, *pft::observe(kPose, m.landmarks()), kPose), floor - 100);
}

// A closed-form sighting is scored in P: the Gaussian of its P about the P
// that the pose predicts, with C_P and the floors mapped through dP/dL.
TEST(CodedLandmarksMap, ClosedFormSightingsAreScoredInPrimary)
{
	CCodedLandmarksMap m(pft::room());
	m.likelihoodOptions.outlier_probability = 0;  // the Gaussian alone
	auto o = pft::observe(kPose, m.landmarks());
	measureInPrimary(*o, m.landmarks());
	ASSERT_GE(o->sightings.size(), 2u);
	const auto& lo = m.likelihoodOptions;
	const double sa = lo.min_std_angle_deg * M_PI / 180;
	const Eigen::Vector3d floors(lo.min_std_range_m * lo.min_std_range_m, sa * sa, sa * sa);
	for (const auto& d : {CPose2D(0, 0, 0), CPose2D(0.03, -0.02, 0.01), CPose2D(-0.2, 0.1, -0.05)})
	{
		const CPose2D p = kPose + d;
		double cx, cy, cc, cs;
		ASSERT_TRUE(CCodedLandmarksMap::cameraInWorld(
			p.x(), p.y(), std::cos(p.phi()), std::sin(p.phi()), o->cameraPose, cx, cy, cc, cs));
		double expected = 0;
		for (const auto& sg : o->sightings)
		{
			const auto* lm = m.find(sg.id);
			const Eigen::Vector3d Lp = CCodedLandmarksMap::predictL(
				cx, cy, cc, cs, lm->x_m, lm->y_m, std::cos(lm->yaw_rad), std::sin(lm->yaw_rad));
			Eigen::Matrix<double, 4, 3> J;
			const Eigen::Vector4d r = sg.P - codemark::pose::primaryFromLandmark(
												 Lp, kLambda, lm->geometry().innerHalf(), &J);
			const Eigen::Matrix4d C = sg.C_P + J * floors.asDiagonal() * J.transpose();
			expected +=
				-0.5 * r.dot(C.inverse() * r) - 0.5 * std::log((2 * M_PI * C).determinant());
		}
		EXPECT_NEAR(loglik(m, *o, p), expected, 1e-6 * std::abs(expected)) << d;
	}
	// The angles of L play no part (its range gives the landmark's size).
	const double before = loglik(m, *o, kPose);
	for (auto& sg : o->sightings) sg.L[1] += 0.1, sg.L[2] -= 0.2;
	EXPECT_NEAR(loglik(m, *o, kPose), before, 1e-9 * std::abs(before));
}

TEST(CodedLandmarksMap, LikelihoodInPrimaryPeaksAtTheTruePose)
{
	const CCodedLandmarksMap m(pft::room());
	auto o = pft::observe(kPose, m.landmarks());
	measureInPrimary(*o, m.landmarks());
	const double at_truth = loglik(m, *o, kPose);
	EXPECT_TRUE(std::isfinite(at_truth));
	for (const auto& d :
		 {CPose2D(0.03, 0, 0), CPose2D(0, -0.03, 0), CPose2D(0, 0, 0.02),
		  CPose2D(-0.1, 0.05, -0.05), CPose2D(1, 1, 1), CPose2D(0, 0, M_PI)})
	{
		const double there = loglik(m, *o, kPose + d);
		EXPECT_TRUE(std::isfinite(there)) << d;
		EXPECT_GT(at_truth, there) << d;
	}
}

TEST(CodedLandmarksMap, OutliersInPrimaryStayFiniteAndBounded)
{
	const CCodedLandmarksMap m(pft::room());
	auto o = pft::observe(kPose, m.landmarks());
	measureInPrimary(*o, m.landmarks());
	const double clean = loglik(m, *o, kPose);
	auto bad = o->sightings.front();
	bad.P[0] += 200;  // a landmark 200 px from where it is
	bad.P[2] += 200;
	o->sightings.push_back(bad);
	const double with_outlier = loglik(m, *o, kPose);
	ASSERT_TRUE(std::isfinite(with_outlier));
	// The mixture's floor: log(p U), U the uniform over the image: x1, x2
	// across its width, y1, y2 up to half its height.
	const double floor =
		std::log(m.likelihoodOptions.outlier_probability) - 2 * std::log(640.0 * 240.0);
	EXPECT_GE(with_outlier - clean, floor - 1e-9);
	EXPECT_LT(with_outlier - clean, floor + 0.1);
	// Seen from behind the printed side: the floor too.
	o->sightings.assign(1, bad);
	const auto* lm = m.find(bad.id);
	const double c = std::cos(lm->yaw_rad), sn = std::sin(lm->yaw_rad);
	const CPose2D behind(lm->x_m - 1.2 * c, lm->y_m - 1.2 * sn, lm->yaw_rad);  // facing its back
	const double from_behind = loglik(m, *o, behind);
	EXPECT_TRUE(std::isfinite(from_behind));
	EXPECT_LE(from_behind, floor + 1e-9);
}

TEST(CodedLandmarksMap, UnknownIdsChangeNothing)
{
	const CCodedLandmarksMap m(pft::room());
	auto o = pft::observe(kPose, m.landmarks());
	const CPose2D other(3, 2.5, -1);
	const double a = loglik(m, *o, kPose), b = loglik(m, *o, other);
	auto s = o->sightings.front();
	s.id = 200;	 // not in the map
	s.L = {1.0, 0.1, 0.2};
	o->sightings.push_back(s);
	EXPECT_EQ(loglik(m, *o, kPose), a);
	EXPECT_EQ(loglik(m, *o, other), b);
}

TEST(CodedLandmarksMap, BearingRangeLikelihoodPeaksAtTheTruth)
{
	const CCodedLandmarksMap m(pft::room());
	const auto o = pft::observe(kPose, m.landmarks());
	const auto br = o->toBearingRange();
	ASSERT_GE(br->sensedData.size(), 2u);
	const double at_truth = loglik(m, *br, kPose);
	ASSERT_TRUE(std::isfinite(at_truth));
	for (const auto& d :
		 {CPose2D(0.05, 0, 0), CPose2D(0, 0.05, 0), CPose2D(0, 0, 0.03), CPose2D(0.5, -0.5, 0.4)})
		EXPECT_GT(at_truth, loglik(m, *br, kPose + d)) << d;

	// Without per-reading covariances: the sensor's standard deviations.
	auto br2 = mrpt::obs::CObservationBearingRange::Create(*br);
	br2->validCovariances = false;
	br2->sensor_std_range = 0.02f;
	br2->sensor_std_yaw = 0.01f;
	br2->sensor_std_pitch = 0;
	const double t2 = loglik(m, *br2, kPose);
	EXPECT_GT(t2, loglik(m, *br2, kPose + CPose2D(0.05, 0, 0)));
	EXPECT_GT(t2, loglik(m, *br2, kPose + CPose2D(0, 0, 0.03)));
}

TEST(CodedLandmarksMap, RepresentationAndVisualization)
{
	const CCodedLandmarksMap m(pft::room());
	const std::string prefix = mrpt::system::getTempFileName();
	m.saveMetricMapRepresentationToFile(prefix);
	const auto back = codemark::LandmarkMap::load(prefix + "_landmarks.txt");
	EXPECT_EQ(back.landmarks.size(), m.landmarks().landmarks.size());
	std::remove((prefix + "_landmarks.txt").c_str());
	mrpt::opengl::CSetOfObjects gl;
	m.getVisualizationInto(gl);
	EXPECT_GE(gl.size(), m.landmarks().landmarks.size());
	EXPECT_FALSE(m.isEmpty());
	EXPECT_TRUE(CCodedLandmarksMap().isEmpty());
}

// --------------------------------------------------------- particle filter
namespace
{
struct RunResult
{
	int frames_with_sightings_to_converge = -1;	 //!< -1: never within 10 cm
	double final_error_m = 1e9;
	bool initialized = false;
};

/** Runs the filter along the circle from step \a k0 to \a k1; \a kidnap_at:
 * the true pose jumps by \a jump there (odometry does not see it). */
RunResult runCircle(
	codemark::filters::Localizer& f, int k0, int k1, std::mt19937& rng, int kidnap_at = -1,
	const CPose2D& jump = CPose2D())
{
	RunResult r;
	const auto map = pft::room();
	int frames_with_sightings = 0;
	CPose2D offset;
	for (int k = k0; k < k1; ++k)
	{
		if (k == kidnap_at) offset = jump;
		const CPose2D truth = offset + pft::circlePose(k);
		const auto odo = pft::odometry(pft::circlePose(k - 1), pft::circlePose(k), rng);
		mrpt::obs::CSensoryFrame sf;
		const auto o = pft::observe(truth, map, &rng, 0.2 * k);
		if (!o->sightings.empty()) ++frames_with_sightings;
		sf.insert(o);
		f.step(k == k0 ? nullptr : &odo, sf);
		const auto e = f.estimate();
		r.final_error_m = positionError(e, truth);
		r.initialized = e.initialized;
		if (r.frames_with_sightings_to_converge < 0 && k >= std::max(k0, kidnap_at) &&
			r.final_error_m < 0.10 && e.initialized)
			r.frames_with_sightings_to_converge = frames_with_sightings;
	}
	return r;
}
}  // namespace

TEST(ParticleFilter, ConvergesFromAUniformStart)
{
	for (int seed : {1, 2, 3})
	{
		auto cfg = shippedConfig(seed);
		const auto f = codemark::filters::makeLocalizer("pf", cfg, pft::room());
		ASSERT_EQ(f->method(), "pf");
		EXPECT_FALSE(f->estimate().initialized);
		std::mt19937 rng(seed);
		const RunResult r = runCircle(*f, 0, 60, rng);
		// The target: converged (< 10 cm) within 3 sightings.
		EXPECT_GE(r.frames_with_sightings_to_converge, 1) << "seed " << seed;
		EXPECT_LE(r.frames_with_sightings_to_converge, 3) << "seed " << seed;
		EXPECT_LT(r.final_error_m, 0.10) << "seed " << seed;
		EXPECT_TRUE(r.initialized);
		const auto e = f->estimate();
		EXPECT_TRUE(e.cov.isApprox(e.cov.transpose()));
		EXPECT_GT(e.cov.determinant(), 0);
	}
}

// From a uniform start, the first frame's cloud is as wide as what the
// frame says: the fixes injected into the uniform cloud are weighted over the
// density they were drawn from; weighted by the likelihood alone they would
// stand for about its square (half the variance along a far sighting's
// poorly measured direction, across the line of sight).
TEST(ParticleFilter, FirstFixIsAsWideAsTheLikelihood)
{
	codemark::LandmarkMap one;
	one.landmarks.push_back(*pft::room().find(5));	// at (6, 2), facing -x
	const CPose2D truth(2.0, 2.0, 0.0);	 // 3.9 m in front of it
	const auto o = pft::observe(truth, one);
	ASSERT_EQ(o->sightings.size(), 1u);
	const auto& sg = o->sightings.front();
	// The likelihood's covariance in the robot's pose, to first order: C_L
	// with the floors, through the pose's Jacobian (sightings of the other
	// kind, in P, are checked above; the injection is the same).
	// Without the outliers' uniform, whose share of the posterior lies
	// metres away and would dominate its variance.
	const std::string section = "MetricMap_codedLandmarksMap_00_likelihoodOpts";
	CCodedLandmarksMap m(one);
	{
		auto cfg = shippedConfig(1);
		m.likelihoodOptions.loadFromConfigFile(cfg, section);
	}
	const Eigen::Matrix3d C_L = m.inflatedCovariance(sg.C_L);
	Eigen::Matrix3d J, C_pose;
	codemark::pose::poseFromLandmark(sg.L, &J);
	codemark::pose::robotPoseInWorld(
		sg.pose_in_landmark, J * C_L * J.transpose(),
		codemark::pose::landmarkPlanarPose(one.landmarks[0].world_T_landmark()),
		codemark::pose::cameraPlanarPose(o->cameraPose), &C_pose);
	for (int seed : {1, 2, 3})
	{
		auto cfg = shippedConfig(seed);
		cfg.write(section, "outlier_probability", 0);
		codemark::filters::ParticleFilterLocalizer f(cfg, one);
		mrpt::obs::CSensoryFrame sf;
		sf.insert(o);
		f.step(nullptr, sf);
		const auto e = f.estimate();
		EXPECT_LT(positionError(e, truth), 3 * std::sqrt(C_pose.block<2, 2>(0, 0).trace()));
		// Across the line of sight (y): 14 cm; along it (x): 4 cm.
		for (int i : {0, 1})
		{
			const double ratio = e.cov(i, i) / C_pose(i, i);
			EXPECT_GT(ratio, 0.7) << "seed " << seed << " axis " << i;
			EXPECT_LT(ratio, 1.4) << "seed " << seed << " axis " << i;
		}
	}
}

// The regularisation moves each particle by N(0, (r h)^2 C): the same
// cloud before it, the covariance after it grows by 1 + (r h)^2. A flat
// likelihood keeps the weights equal, so that the sample covariances are
// those of all the particles.
TEST(ParticleFilter, RegularisationWidensTheCloudByItsKernel)
{
	constexpr int kParticles = 2000;
	codemark::filters::PoseEstimate init;
	init.initialized = true;
	init.mean = kPose;
	init.cov = Eigen::Vector3d(0.04, 0.04, 0.01).asDiagonal();
	std::mt19937 rng(3);
	mrpt::obs::CSensoryFrame sf;
	sf.insert(pft::observe(kPose, pft::room(), &rng));
	auto cloud = [&](double roughening)
	{
		auto cfg = shippedConfig(4);
		cfg.write("PF_options", "adaptiveSampleSize", 0);
		cfg.write("ParticleFilter", "particles_count", kParticles);
		cfg.write("ParticleFilter", "roughening", roughening);
		cfg.write("MetricMap_codedLandmarksMap_00_likelihoodOpts", "sigma_scale", 1e4);
		codemark::filters::ParticleFilterLocalizer f(cfg, pft::room(), init);
		f.step(nullptr, sf);
		EXPECT_EQ(f.particles().m_particles.size(), size_t(kParticles));
		return f.estimate().cov;
	};
	const Eigen::Matrix3d plain = cloud(0);
	for (const double r : {2.0, 4.0})
	{
		const Eigen::Matrix3d rough = cloud(r);
		const double h2 = r * r * std::pow(4.0 / (kParticles * 5.0), 2.0 / 7.0);
		for (int i = 0; i < 3; ++i)
			EXPECT_NEAR(rough(i, i) / plain(i, i), 1 + h2, 0.2 * h2) << "r " << r << " axis " << i;
	}
}

TEST(ParticleFilter, RecoversFromAKidnapping)
{
	auto cfg = shippedConfig(7);
	codemark::filters::ParticleFilterLocalizer f(cfg, pft::room());
	std::mt19937 rng(7);
	const RunResult before = runCircle(f, 0, 30, rng);
	ASSERT_LT(before.final_error_m, 0.10);
	const int injections = f.injections();
	// Carried 1.5 m away and turned: the odometry knows nothing of it.
	const RunResult after = runCircle(f, 30, 110, rng, 30, CPose2D(-1.2, 0.9, 0.0));
	EXPECT_GT(f.injections(), injections);
	EXPECT_GE(after.frames_with_sightings_to_converge, 1);
	EXPECT_LT(after.final_error_m, 0.10);
}

TEST(ParticleFilter, StartsAroundAGivenPose)
{
	auto cfg = shippedConfig(5);
	codemark::filters::PoseEstimate init;
	init.initialized = true;
	init.mean = pft::circlePose(0);
	init.cov = Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal();
	const auto f = codemark::filters::makeLocalizer("pf", cfg, pft::room(), init);
	EXPECT_TRUE(f->estimate().initialized);
	EXPECT_LT(positionError(f->estimate(), pft::circlePose(0)), 0.05);
	std::mt19937 rng(5);
	const RunResult r = runCircle(*f, 0, 40, rng);
	EXPECT_LT(r.final_error_m, 0.10);
}

TEST(ParticleFilter, CountsUnknownIdsAndRejectsWrongSightings)
{
	auto cfg = shippedConfig(9);
	const auto f = codemark::filters::makeLocalizer("pf", cfg, pft::room());
	std::mt19937 rng(9);
	runCircle(*f, 0, 20, rng);
	ASSERT_TRUE(f->estimate().initialized);
	const CPose2D truth = pft::circlePose(20);
	auto o = pft::observe(truth, pft::room(), nullptr, 4.0);
	ASSERT_FALSE(o->sightings.empty());
	const size_t good = o->sightings.size();
	auto unknown = o->sightings.front();
	unknown.id = 250;
	auto wrong = o->sightings.front();
	wrong.L[0] += 1.0;	// a planted sighting 1 m off
	o->sightings.push_back(unknown);
	o->sightings.push_back(wrong);
	mrpt::obs::CSensoryFrame sf;
	sf.insert(o);
	const auto odo = pft::odometry(pft::circlePose(19), pft::circlePose(20), rng);
	const auto st = f->step(&odo, sf);
	EXPECT_EQ(st.unknown_id, 1);
	EXPECT_EQ(st.rejected, 1);
	EXPECT_EQ(st.used, static_cast<int>(good));
	EXPECT_LT(positionError(f->estimate(), truth), 0.10);
}

// A huge but finite odometry increment passes the stepper's input checks;
// the particles then overflow: a clear error, not a NaN estimate.
TEST(ParticleFilter, NonFiniteParticlesOrCovarianceThrow)
{
	auto cfg = shippedConfig(1);
	codemark::filters::PoseEstimate start;
	start.initialized = true;
	start.mean = kPose;
	start.cov = Eigen::Matrix3d::Identity() * 1e-4;
	const auto f = codemark::filters::makeLocalizer("pf", cfg, pft::room(), start);
	mrpt::obs::CActionRobotMovement2D act;
	mrpt::obs::CActionRobotMovement2D::TMotionModelOptions mm;
	mm.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
	// Noise independent of the distance, so that the action's own
	// covariance stays finite (MRPT ignores an action with an infinite one).
	mm.gaussianModel.a1 = mm.gaussianModel.a2 = mm.gaussianModel.a3 = mm.gaussianModel.a4 = 0;
	mm.gaussianModel.minStdXY = 0.01;
	mm.gaussianModel.minStdPHI = 0.01;
	act.computeFromOdometry(CPose2D(0.1, 0, 0), mm);
	mrpt::obs::CSensoryFrame none;
	EXPECT_NO_THROW(f->step(&act, none));
	// Steps of 1e308 m with a small, finite covariance (set directly: MRPT's
	// motion models overflow on such a distance): the particles' spread and
	// then their positions overflow.
	act.poseChange = mrpt::poses::CPosePDFGaussian::Create(
		CPose2D(1e308, 0, 0), mrpt::math::CMatrixDouble33(Eigen::Matrix3d::Identity() * 1e-4));
	try
	{
		f->step(&act, none);
		f->step(&act, none);
		ADD_FAILURE() << "no error on an overflowing particle set";
	}
	catch (const std::runtime_error& e)
	{
		EXPECT_NE(std::string(e.what()).find("pf: "), std::string::npos) << e.what();
		EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
	}
}

// The same through codemark-localize's run: the error names the rawlog
// entry (the app prints it on one line and exits 1).
TEST(ParticleFilter, NonFiniteStateInARunNamesTheRawlogEntry)
{
	const std::string dir =
		mrpt::system::getTempFileName() + "_pf_nonfinite_" + std::to_string(getpid());
	mrpt::system::createDirectory(dir);
	pft::room().save(dir + "/map.txt");
	const std::string rawlog = dir + "/in.rawlog";
	{
		mrpt::io::CFileGZOutputStream f(rawlog);
		auto ar = mrpt::serialization::archiveFrom(f);
		for (int k = 0; k < 4; ++k)
		{
			mrpt::obs::CActionCollection acts;
			mrpt::obs::CActionRobotMovement2D a;
			a.computeFromOdometry(CPose2D(0.05, 0, 0), pft::motionModel());
			if (k == 2)	 // entry #4: finite, absurd (not odometry: MRPT would
			{  // recompute the PDF from the raw reading when reading it)
				a.estimationMethod = mrpt::obs::CActionRobotMovement2D::emScan2DMatching;
				a.poseChange = mrpt::poses::CPosePDFGaussian::Create(
					CPose2D(1e308, 0, 0),
					mrpt::math::CMatrixDouble33(Eigen::Matrix3d::Identity() * 1e-4));
			}
			acts.insert(a);
			ar << acts;
			mrpt::obs::CSensoryFrame sf;
			sf.insert(pft::observe(kPose, pft::room(), nullptr, 0.2 * k));
			ar << sf;
		}
	}
	codemark::eval::LocalizeRequest req;
	req.config_file = std::string(CODEMARK_SOURCE_SHARE_DIR) + "/config/pf.ini";
	req.method = "pf";
	req.rawlog = rawlog;
	req.map_file = dir + "/map.txt";
	try
	{
		codemark::eval::runLocalization(req);
		ADD_FAILURE() << "no error: " << dir;
		return;
	}
	catch (const std::exception& e)
	{
		const std::string m = e.what();
		EXPECT_NE(m.find("in.rawlog: entry #5"), std::string::npos) << m;
		EXPECT_NE(m.find("non-finite"), std::string::npos) << m;
	}
	mrpt::system::deleteFilesInDirectory(dir, true);
}

TEST(ParticleFilter, BadConfigurationThrows)
{
	auto cfg = shippedConfig(1);
	cfg.write("ParticleFilter", "particles_count", 0);
	EXPECT_THROW(codemark::filters::makeLocalizer("pf", cfg, pft::room()), std::invalid_argument);
	auto cfg2 = shippedConfig(1);
	EXPECT_THROW(
		codemark::filters::makeLocalizer("pf", cfg2, codemark::LandmarkMap()),
		std::invalid_argument);
	auto cfg3 = shippedConfig(1);
	cfg3.write("MetricMap_codedLandmarksMap_00_likelihoodOpts", "outlier_probability", 1.5);
	EXPECT_THROW(codemark::filters::makeLocalizer("pf", cfg3, pft::room()), std::invalid_argument);
	// A negative regularisation is refused with its key.
	auto cfg4 = shippedConfig(1);
	cfg4.write("ParticleFilter", "roughening", -0.1);
	try
	{
		codemark::filters::makeLocalizer("pf", cfg4, pft::room());
		ADD_FAILURE() << "no error";
	}
	catch (const std::invalid_argument& e)
	{
		EXPECT_NE(std::string(e.what()).find("roughening"), std::string::npos) << e.what();
	}
}
