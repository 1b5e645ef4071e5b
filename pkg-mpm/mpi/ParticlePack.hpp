// Particles moving between MPI ranks (MPI build only; doc/developer/scaling.md): one particle's fields packed
// into doubles in a fixed order, the arrivals appended in that order, the leavers dropped in place; the optional
// fields some rank holds are created (zero) on every rank so every rank packs the same fields.
#pragma once
#include "../core/Particles.hpp"
#include <cstring>
#include <vector>

#ifdef MPM_MPI
namespace mpm {

template <int D>
struct ParticlePack {
	static size_t fieldCount(Particles<D>& P)
	{
		size_t n = 2; // id, material
		P.forEachRealField([&](std::vector<Real>&) { ++n; });
		return n;
	}
	static void pack(Particles<D>& P, size_t p, std::vector<double>& buf)
	{
		P.forEachRealField([&](std::vector<Real>& f) { buf.push_back(f[p]); });
		double id;
		std::memcpy(&id, &P.id[p], sizeof id); // the 64 bits as they are
		buf.push_back(id), buf.push_back(double(P.mat[p]));
	}
	// Keeps the particles with go[p] == 0, in their order.
	static void keep(Particles<D>& P, const std::vector<uint8_t>& go)
	{
		size_t k = 0;
		auto   compact = [&](auto& f) {
			k = 0;
			for (size_t p = 0; p < P.n; ++p)
				if (!go[p]) f[k++] = f[p];
			f.resize(k);
		};
		P.forEachRealField(compact);
		compact(P.id), compact(P.mat);
		P.n = k;
	}
	// The optional fields flagged in opt (traction, damage state, flaw counts), zero-filled where missing.
	static void ensureFields(Particles<D>& P, const double* opt)
	{
		if (opt[0] > 0 && !P.hasTraction())
			for (int a = 0; a < D; ++a) P.trac[a].assign(P.n, 0.0);
		if (opt[1] > 0 && !P.hasDamageState())
			for (auto* f : { &P.epsP, &P.damage, &P.eps0 }) f->assign(P.n, 0.0);
		if (opt[2] > 0 && P.nFlaw.empty()) P.nFlaw.assign(P.n, 0.0);
	}
	static void unpack(Particles<D>& P, const std::vector<double>& buf, size_t count, size_t nf, const double* opt)
	{
		if (!count) return;
		const size_t n0 = P.n;
		P.n += count;
		ensureFields(P, opt); // a rank without particles had none of them (empty arrays)
		size_t i = 0; // field index, in pack's order
		P.forEachRealField([&](std::vector<Real>& f) {
			f.reserve(P.n), f.resize(P.n); // exact growth (no doubling)
			for (size_t j = 0; j < count; ++j) f[n0 + j] = buf[j * nf + i];
			++i;
		});
		P.id.reserve(P.n), P.mat.reserve(P.n), P.id.resize(P.n), P.mat.resize(P.n);
		for (size_t j = 0; j < count; ++j) {
			std::memcpy(&P.id[n0 + j], &buf[j * nf + i], sizeof(int64_t));
			P.mat[n0 + j] = uint8_t(buf[j * nf + i + 1]);
		}
	}
};

} // namespace mpm
#endif
