// C++ unit tests of the rigid surfaces of PTS contact (RigidSurface.hpp): signed distance and outward
// normal of boxes checked against closed triangle / segment meshes of the same box (two independent
// computations), planes, open surfaces, closedness detection, and the rigid velocity v + ω × (x − c)
// against a finite difference of the moving body.
#include "contact/RigidSurface.hpp"
#include "Check.hpp"
#include <cstdio>
#include <random>

using namespace mpm;

template <int D>
typename Dim<D>::Mat rotation(Real a, Real b)
{
	if constexpr (D == 2) {
		typename Dim<2>::Mat R;
		R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
		return R;
	} else return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(b, Eigen::Vector3d(1, 1, 0).normalized())).toRotationMatrix();
}

// The same oriented box as a BoxPrim in group gb and as a closed mesh in group gm (part frame corners).
template <int D>
void boxAsMesh(RigidGroup<D>& gm, const typename Dim<D>::Vec& h)
{
	using Vec = typename Dim<D>::Vec;
	auto add  = [&](std::initializer_list<Vec> vs) {
		for (const auto& v : vs) gm.elemL.push_back(v), gm.elem.push_back(v);
		gm.elemPart.push_back(0);
	};
	if constexpr (D == 2) {
		Vec c[4] = { Vec(-h[0], -h[1]), Vec(h[0], -h[1]), Vec(h[0], h[1]), Vec(-h[0], h[1]) };
		for (int k = 0; k < 4; ++k) add({ c[k], c[(k + 1) % 4] });
	} else {
		auto C = [&](int i) { return Vec((i & 1 ? 1 : -1) * h[0], (i & 2 ? 1 : -1) * h[1], (i & 4 ? 1 : -1) * h[2]); };
		const int q[6][4] = { { 0, 1, 3, 2 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 3, 7, 6 }, { 0, 2, 6, 4 }, { 1, 3, 7, 5 } };
		for (auto& f : q) add({ C(f[0]), C(f[1]), C(f[2]) }), add({ C(f[0]), C(f[2]), C(f[3]) });
	}
}

template <int D>
void boxVersusMesh()
{
	using Vec = typename Dim<D>::Vec;
	std::vector<RigidPart<D>> parts(1);
	Vec h;
	for (int a = 0; a < D; ++a) h[a] = 0.3 + 0.2 * a;
	Vec c = Vec::Constant(0.7);
	parts[0].setState(c, rotation<D>(0.4, 0.7), Vec::Zero(), SpinOf<D>::Zero());
	RigidGroup<D> gb, gm;
	gb.boxes.push_back({ 0, Vec::Zero(), h, Dim<D>::Mat::Identity(), Vec::Zero(), Dim<D>::Mat::Identity() });
	boxAsMesh<D>(gm, h);
	gb.update(parts), gm.update(parts);
	CHECK(gm.closed, "the box surface mesh must be detected closed");
	std::mt19937                     rng(3);
	std::uniform_real_distribution<> U(-0.5, 2.0);
	int                              inside = 0;
	for (int k = 0; k < 4000; ++k) {
		Vec x;
		for (int a = 0; a < D; ++a) x[a] = U(rng);
		auto hb = gb.query(x), hm = gm.query(x);
		inside += hb.d < 0;
		CHECK(std::abs(hb.d - hm.d) < 1e-12, "D=%d signed distance box %g mesh %g", D, hb.d, hm.d);
		CHECK(std::abs(hb.n.norm() - 1) < 1e-12, "unit normal");
		// the closest point x − d n lies on the surface: distance 0 there
		Vec  s  = x - hb.d * hb.n;
		Real ds = gb.query(s).d;
		CHECK(std::abs(ds) < 1e-12, "closest point off the surface by %g", ds);
		// outward: moving along n increases the distance (away from edges/corners ties)
		if (std::abs(hb.d) > 1e-3 && std::abs(hb.n.dot(hm.n) - 1) < 1e-9) {
			Real dp = gb.query(x + 1e-4 * hb.n).d;
			CHECK(dp > hb.d, "normal is not outward");
		}
	}
	CHECK(inside > 100, "too few samples inside (%d)", inside);
	// an open mesh (one element removed) is a thin two-sided surface: unsigned distance
	RigidGroup<D> go = gm;
	go.elemPart.pop_back(), go.elemL.resize(go.elemL.size() - D), go.elem.resize(go.elem.size() - D);
	go.topologyKnown = false;
	go.update(parts);
	CHECK(!go.closed, "a mesh with a missing element must be open");
	CHECK(go.query(c).d > 0, "open surface distance must be unsigned");
}

template <int D>
void planes()
{
	using Vec = typename Dim<D>::Vec;
	std::vector<RigidPart<D>> parts(1);
	Vec c = Vec::Zero();
	c[1]  = 0.5;
	parts[0].setState(c, Dim<D>::Mat::Identity(), Vec::Zero(), SpinOf<D>::Zero());
	Vec n = Vec::Zero();
	n[1]  = 1;
	RigidGroup<D> one, two;
	one.planes.push_back({ 0, Vec::Zero(), n, false, Vec::Zero(), n });
	two.planes.push_back({ 0, Vec::Zero(), n, true, Vec::Zero(), n });
	one.update(parts), two.update(parts);
	Vec x = Vec::Constant(0.2); // 0.3 below the plane y = 0.5
	CHECK(std::abs(one.query(x).d + 0.3) < 1e-15 && one.query(x).n[1] == 1, "one-sided plane: inside the half-space");
	CHECK(std::abs(two.query(x).d - 0.3) < 1e-15 && two.query(x).n[1] == -1, "two-sided plane: normal towards the point");
	Vec lo, hi;
	one.bounds(0.1, 0.2, lo, hi);
	CHECK(std::abs(lo[1] - 0.3) < 1e-15 && std::abs(hi[1] - 0.6) < 1e-15 && std::isinf(lo[0]), "plane slab bounds");
}

// v + ω × (x − c) equals the time derivative of a material point of a spinning, translating body.
template <int D>
void rigidVelocity()
{
	using Vec = typename Dim<D>::Vec;
	RigidPart<D> q;
	SpinOf<D>    w;
	for (int k = 0; k < w.size(); ++k) w[k] = 0.3 + 0.4 * k;
	Vec v = Vec::Constant(-0.2), c = Vec::Constant(1.0), xl = Vec::Constant(0.25);
	xl[0]            = -0.4;
	const auto R0    = rotation<D>(0.3, 0.2);
	q.setState(c, R0, v, w);
	auto at = [&](Real t) { // x(t) = c + v t + exp(t [ω]×) R0 xl
		typename Dim<D>::Mat Rt;
		if constexpr (D == 2) Rt = rotation<2>(w[0] * t, 0);
		else Rt = Eigen::AngleAxisd(w.norm() * t, w.normalized()).toRotationMatrix();
		return Vec(c + v * t + Rt * R0 * xl);
	};
	const Real dt = 1e-6;
	Vec        fd = (at(dt) - at(-dt)) / (2 * dt);
	Vec        an = q.velocityAt(at(0));
	CHECK((fd - an).norm() < 1e-8, "D=%d rigid velocity %g off the finite difference", D, (fd - an).norm());
	// moment of a force: r × f about c, so the torque of a force through c vanishes
	Vec f = Vec::Constant(2.0);
	CHECK(momentOf<D>(Vec::Zero(), f).norm() == 0, "moment arm zero");
}

void badInput()
{
	ContactParams p;
	bool          threw = false;
	p.chi               = 1.0;
	try {
		p.validate();
	} catch (const InputError& e) {
		threw = std::string(e.what()).find("chi") != std::string::npos;
	}
	CHECK(threw, "chi = 1 must be refused naming chi");
	RigidPart<2> q;
	threw = false;
	try {
		q.setState(Dim<2>::Vec::Zero(), 2 * Dim<2>::Mat::Identity(), Dim<2>::Vec::Zero(), SpinOf<2>::Zero());
	} catch (const InputError&) {
		threw = true;
	}
	CHECK(threw, "a non-rotation orientation must be refused");
}

int main()
{
	boxVersusMesh<2>();
	boxVersusMesh<3>();
	planes<2>();
	planes<3>();
	rigidVelocity<2>();
	rigidVelocity<3>();
	badInput();
	std::printf("%s (%d failures)\n", failures ? "FAILED" : "OK", failures);
	return failures ? 1 : 0;
}
