#include "raster.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace codemark::sim::detail
{
namespace
{
constexpr int kMaxVertices = 64;
using Buffer = std::array<Eigen::Vector2d, kMaxVertices>;

/** Keeps the part of in[0..n) with sign * (coordinate axis of p) <= limit;
 * returns the new vertex count. */
int clipAxis(const Buffer& in, int n, Buffer& out, int axis, double sign, double limit)
{
	int m = 0;
	for (int i = 0; i < n; ++i)
	{
		const Eigen::Vector2d& a = in[i];
		const Eigen::Vector2d& b = in[(i + 1) % n];
		const double da = sign * a[axis] - limit, db = sign * b[axis] - limit;
		const bool ina = da <= 0, inb = db <= 0;
		if (ina) out[m++] = a;
		if (ina != inb) out[m++] = a + (b - a) * (da / (da - db));
	}
	return m;
}

double bufferArea(const Buffer& p, int n)
{
	double a = 0;
	for (int i = 0; i < n; ++i)
	{
		const Eigen::Vector2d& p0 = p[i];
		const Eigen::Vector2d& p1 = p[(i + 1) % n];
		a += p0.x() * p1.y() - p1.x() * p0.y();
	}
	return 0.5 * a;
}
}  // namespace

double signedArea(const Polygon2& poly)
{
	double a = 0;
	const size_t n = poly.size();
	for (size_t i = 0; i < n; ++i)
	{
		const Eigen::Vector2d& p0 = poly[i];
		const Eigen::Vector2d& p1 = poly[(i + 1) % n];
		a += p0.x() * p1.y() - p1.x() * p0.y();
	}
	return 0.5 * a;
}

double pixelCoverage(const Polygon2& poly, double u, double v)
{
	const int n = static_cast<int>(poly.size());
	if (n < 3) return 0.0;
	if (n + 8 > kMaxVertices)
		throw std::invalid_argument("pixelCoverage: polygon has too many vertices");
	// Pixel-local coordinates keep the clipped area free of cancellation.
	Buffer a, b;
	for (int i = 0; i < n; ++i) a[i] = poly[i] - Eigen::Vector2d(u, v);
	int m = clipAxis(a, n, b, 0, +1.0, 0.5);
	m = clipAxis(b, m, a, 0, -1.0, 0.5);
	m = clipAxis(a, m, b, 1, +1.0, 0.5);
	m = clipAxis(b, m, a, 1, -1.0, 0.5);
	if (m < 3) return 0.0;
	return std::abs(bufferArea(a, m));
}

void accumulateCoverage(
	const Polygon2& poly_in, cv::Mat& acc, const cv::Point& origin, double weight)
{
	CV_Assert(acc.type() == CV_64FC1);
	if (poly_in.size() < 3) return;
	const double area = signedArea(poly_in);
	if (!(std::abs(area) > 1e-12)) return;
	Polygon2 poly = poly_in;
	if (area < 0) std::reverse(poly.begin(), poly.end());

	double minx = poly[0].x(), maxx = minx, miny = poly[0].y(), maxy = miny;
	for (const auto& p : poly)
	{
		minx = std::min(minx, p.x());
		maxx = std::max(maxx, p.x());
		miny = std::min(miny, p.y());
		maxy = std::max(maxy, p.y());
	}
	// Pixel u overlaps the polygon only if u + 0.5 > minx and u - 0.5 < maxx.
	const double lo_u = std::max(std::ceil(minx - 0.5), double(origin.x));
	const double hi_u = std::min(std::floor(maxx + 0.5), double(origin.x + acc.cols - 1));
	const double lo_v = std::max(std::ceil(miny - 0.5), double(origin.y));
	const double hi_v = std::min(std::floor(maxy + 0.5), double(origin.y + acc.rows - 1));
	if (lo_u > hi_u || lo_v > hi_v) return;
	const int u0 = static_cast<int>(lo_u), u1 = static_cast<int>(hi_u);
	const int v0 = static_cast<int>(lo_v), v1 = static_cast<int>(hi_v);

	// Edge half-planes a u + b v + c >= 0 inside (counter-clockwise polygon),
	// (a, b) a unit normal; r is the half extent of the pixel square along it.
	struct Edge
	{
		double a, b, c, r;
	};
	std::vector<Edge> edges;
	edges.reserve(poly.size());
	for (size_t i = 0; i < poly.size(); ++i)
	{
		const Eigen::Vector2d& p = poly[i];
		const Eigen::Vector2d e = poly[(i + 1) % poly.size()] - p;
		const double len = e.norm();
		if (!(len > 1e-12)) continue;
		const double a = -e.y() / len, b = e.x() / len;
		edges.push_back({a, b, -(a * p.x() + b * p.y()), 0.5 * (std::abs(a) + std::abs(b))});
	}

	for (int v = v0; v <= v1; ++v)
	{
		double* row = acc.ptr<double>(v - origin.y);
		for (int u = u0; u <= u1; ++u)
		{
			bool inside = true, outside = false;
			for (const Edge& e : edges)
			{
				const double d = e.a * u + e.b * v + e.c;
				if (d <= -e.r)
				{
					outside = true;
					break;
				}
				if (d < e.r) inside = false;
			}
			if (outside) continue;
			row[u - origin.x] += inside ? weight : weight * pixelCoverage(poly, u, v);
		}
	}
}

Polygon3 clipNear(const Polygon3& poly, double z_min)
{
	Polygon3 out;
	const size_t n = poly.size();
	out.reserve(n + 1);
	for (size_t i = 0; i < n; ++i)
	{
		const Eigen::Vector3d& a = poly[i];
		const Eigen::Vector3d& b = poly[(i + 1) % n];
		const double da = a.z() - z_min, db = b.z() - z_min;
		const bool ina = da >= 0, inb = db >= 0;
		if (ina) out.push_back(a);
		if (ina != inb) out.push_back(a + (b - a) * (da / (da - db)));
	}
	if (out.size() < 3) out.clear();
	return out;
}

Polygon2 projectPinhole(const Polygon3& poly, double fx, double fy, double cx, double cy)
{
	Polygon2 out;
	out.reserve(poly.size());
	for (const auto& p : poly) out.emplace_back(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
	return out;
}

}  // namespace codemark::sim::detail
