#pragma once
/** \file edge_models.h
 * Internal: the parts of the sub-pixel stage (stage 7). A side's profiles
 * across it (SideProfiles), what is measured on them (SideProperties), the
 * edge locators that place the inner edge in one profile (EdgeLocator, one
 * per model of the edge), and the policy that picks a locator from the
 * side's properties (chooseLocator()). refineQuadrangle() strings them
 * together with the side models that correct a whole side (the clip's
 * imputation, the levels' rounding, the thin frame's print model) and the
 * line fit (fitLine()).
 */
#include "stages.h"

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace codemark::detect
{
/** The G and -(R + B) profiles of one side of a coarse quadrangle, one per
 * row (a mostly vertical side) or column, across the side and pointing into
 * the fill, so that the inner edge rises in G. Sample i of profile j lies
 * at across coordinate origin[j] + inward (i - half), along coordinate
 * pos[j]. */
struct SideProfiles
{
	int side = 0;  //!< top, right, bottom, left
	int along = 1;	//!< the axis the profiles step along (0 u, 1 v)
	int across = 0;	 //!< the axis they run across (1 - along)
	int inward = 1;	 //!< +1 or -1: the across direction into the fill
	int n = 0;	//!< samples per profile (2 half + 1)
	int half = 0;  //!< the coarse line's sample
	int lo = 0, hi = 0;	 //!< the search window around it (sample indices)
	/** The black frame's and the green band's widths across the side
	 * [px], from the coarse quadrangle's extent and the landmark's
	 * proportions (perspective: in the ratio of this side's length to the
	 * mean of it and the opposite one's). */
	double frame_px = 0, fill_px = 0;
	/** n samples per profile: G (luma after readLumaProfiles()) and
	 * -(R + B). */
	std::vector<int> g, rb;
	std::vector<int> pos, origin;  //!< per profile [px]
	/** Profiles whose fill side (beyond the search window) averages at
	 * least SubpixelParams::saturation_level, and of those the ones that
	 * reach 254 within two samples after their steepest rise. */
	int saturated = 0, clipped = 0;

	size_t count() const { return pos.size(); }
	const int* gAt(size_t j) const { return g.data() + j * n; }
	const int* rbAt(size_t j) const { return rb.data() + j * n; }
	/** The image point [raw px] of an edge at sample coordinate \a e of
	 * profile \a j. */
	Eigen::Vector2d point(size_t j, double e) const;
};

/** The profiles of side \a side of \a coarse (corner k to corner k + 1),
 * clear of the corners by SubpixelParams::corner_margin_px, each
 * search_px + reach_px + 2 samples either side of the coarse line; rows or
 * columns whose profile would leave the image are skipped. */
SideProfiles readSideProfiles(
	const cv::Mat& bgr, const Quad& coarse, int side, double frame_ratio, double fill_ratio,
	const SubpixelParams& p);

/** \a side's profiles (G) read again in luma (lumaLevel()) at the same
 * samples. */
void readLumaProfiles(const cv::Mat& bgr, SideProfiles& side);

/** Whether a side's edges read in luma (\a luma, \a luma_edges: the same
 * profiles through readLumaProfiles()) are sharper than in G (\a green,
 * \a green_edges): each profile's response width (the second moment of
 * its central differences within 3 samples on the edge's fill side), G's
 * less luma's, must have its median at least 3 of its standard errors
 * above 0 (medianWithError()) and at least 15% of G's own, over at least
 * 5 profiles. Where the colour has the image's full resolution, G
 * and luma see one edge shape and G is the better read (luma adds the R
 * and B channels' noise for little contrast); a camera's chroma
 * subsampling, its JPEG's coarser chroma or its demosaicing widens G's
 * edge and not luma's. */
bool lumaIsSharper(
	const SideProfiles& green, const std::vector<std::optional<double>>& green_edges,
	const SideProfiles& luma, const std::vector<std::optional<double>>& luma_edges);

/** What the locator policy reads of a side. */
struct SideProperties
{
	double frame_px = 0;  //!< the black frame's width across it [px]
	/** Most profiles' fills at the sensor's top (SideProfiles::saturated),
	 * and none of the clip's restorations applied. */
	bool saturated = false;
	/** Most profiles reach the top within two samples of their steepest
	 * rise (SideProfiles::clipped): the clip cuts the edge's response. */
	bool clipped = false;
};

/** The side's properties as \a side's profiles show them: saturated and
 * clipped where more than half of its profiles are. */
SideProperties measureSide(const SideProfiles& side);

/** The edge models a locator can apply. */
enum class LocatorKind
{
	/** G's derivative centroid: exact for any symmetric point-spread
	 * function where nothing else lies within its reach. */
	Centroid,
	/** G's derivative peak from its three samples (the pixel-integrated
	 * step's exact response), with the lobe of the frame's outer edge a
	 * frame width outside removed: a thin frame, or a clipped fill whose
	 * response lost its bright half. */
	Peak,
	/** -(R + B)'s isolated centroid next to G's peak: a fill clipped right
	 * into its edges, where G's response is cut and R + B (dark in the
	 * fill, unclipped in the frame) is not. */
	Channels
};
const char* locatorName(LocatorKind kind);

/** A locator, the channel it reads and its one parameter. */
struct LocatorChoice
{
	LocatorKind kind = LocatorKind::Centroid;
	/** Peak: the outer edge's distance before the inner one [px]; 0 for
	 * none modelled. */
	double outer_edge_px = 0;
	EdgeChannel channel = EdgeChannel::Green;
};

/** The policy: the locator for a side with the properties \a s. Centroid
 * where the frame is wide (SubpixelParams::min_frame_px_centroid) and the
 * fill unsaturated; Peak with the outer edge's lobe on a thin frame; on a
 * saturated fill Peak (its centroid would lean towards the frame), unless
 * the clip reaches the edges of a wide frame: Channels. The centroid may
 * read luma (lumaLevel(): free of the camera's chroma planes; where its
 * edges are the sharper, lumaIsSharper()), the others read G: on
 * a thin frame the wall beyond its outer edge is brighter against the
 * fill in luma than in G (about 3x an office inkjet green's luma, 2x its
 * G), and that edge's lobe then outweighs the inner edge's response in
 * the peak's three samples; a clipped fill is clipped in G, which luma
 * carries. \a models switches the outer edge's lobe and luma off for
 * experiments. */
LocatorChoice chooseLocator(
	const SideProperties& s, const SubpixelParams& p, const SubpixelModels& models = {});

/** Places the rising edge of one profile. */
class EdgeLocator
{
   public:
	virtual ~EdgeLocator() = default;
	/** The edge [sample coordinate] of the profile \a g (G) and \a rb
	 * (-(R + B)) of \a n samples within lo..hi; nullopt where G's steepest
	 * rise there is below the locator's smallest slope. */
	virtual std::optional<double> locate(
		const int* g, const int* rb, int n, int lo, int hi) const = 0;
};

/** The locator for \a choice: edges rising by at least \a min_rise grey
 * levels a pixel, read with \a p's reach and floor. */
std::unique_ptr<EdgeLocator> makeLocator(
	const LocatorChoice& choice, double min_rise, const SubpixelParams& p,
	const SubpixelModels& models = {});

/** Each profile's edge through \a locator, the green fill just inside it
 * (G two samples inwards above the mean of R and B by a quarter of G: a
 * printed green through any transfer curve is, white paper and grey walls
 * are not); where it is not, the search is repeated inwards of the
 * rejected edge (the sheet's edge against a darker wall rises inwards
 * too, a frame and a margin outside). */
std::vector<std::optional<double>> locateEdges(
	const SideProfiles& side, const EdgeLocator& locator);

/** The median slope [grey levels per sample] of \a side's G profiles at
 * their located \a edges (central differences); 0 where none is located. */
double edgeSlope(const SideProfiles& side, const std::vector<std::optional<double>>& edges);

/** The image points [undistorted px with \a camera's distortion] of the
 * located \a edges, for the line fit. */
std::vector<Eigen::Vector2d> edgePoints(
	const SideProfiles& side, const std::vector<std::optional<double>>& edges,
	const CameraModel& camera);

}  // namespace codemark::detect
