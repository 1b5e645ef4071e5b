// The contact phase of the step (paper Sec. 2.3, Eqs. 23–26; Fig. 1b): particle-to-surface (PTS) frictional contact
// of the particles with rigid surfaces, group by group with each group's law. beforeTransfer (serial, before P2G)
// places the bodies and excludes the nodes they cover; apply (every thread, between gridUpdate and g2p) corrects the
// nodal velocities and sums the reactions; reproject (after the late damping) runs the kinematic groups again;
// afterRemap corrects the MUSL velocities at the kinematic groups' nodes.
// The ContactStep's exchange policy (core/Exchange.hpp) carries what a distributed run shares.
#pragma once
#include "KinematicContact.hpp"
#include "PenaltyContact.hpp"

namespace mpm {

// The layers: the per-step state (ContactDetection), then each law over it.
template <int D>
class PtsContact : public KinematicContact<D, PenaltyContact<D, ContactDetection<D>>> {
public:
	using ContactGroups<D>::parts;
	using ContactGroups<D>::groups;
	using ContactDetection<D>::work;

	template <class X>
	void beforeTransfer(const ContactStep<D, X>& s)
	{
		ContactDetection<D>::beforeTransfer(s);
		this->preparePenalty();
		for (size_t gi = 0; gi < groups.size(); ++gi)
			if (work[gi].skip) this->idleKinematic(gi); // no contacts this step: the next ones start from zero
	}
	template <class X>
	void apply(const ContactStep<D, X>& s)
	{
		for (size_t gi = 0; gi < groups.size(); ++gi) {
			if (work[gi].skip) continue;
			if (groups[gi].params.law == ContactLaw::Kinematic) s.exchange.oneThread([&] { this->applyKinematic(gi, s); });
			else this->applyPenalty(gi, s);
		}
		if (s.exchange.distributed()) s.exchange.oneThread([&] { sumReactions(s.exchange); }); // every process's reactions
	}
	template <class X>
	void reproject(const ContactStep<D, X>& s)
	{
		if (!hasKinematic()) return;
		s.exchange.oneThread([&] {
			const bool dist = s.exchange.distributed(); // the reactions' changes are summed over the processes like apply's
			if (dist) {
				kept.assign(parts.begin(), parts.end());
				for (auto& q : parts) q.force.setZero(), q.torque.setZero();
			}
			for (size_t gi = 0; gi < groups.size(); ++gi)
				if (groups[gi].params.law == ContactLaw::Kinematic && !work[gi].skip) this->reprojectKinematic(gi, s);
			if (dist) {
				sumReactions(s.exchange);
				for (size_t p = 0; p < parts.size(); ++p) parts[p].force += kept[p].force, parts[p].torque += kept[p].torque;
			}
		});
	}

	// After the MUSL remap (every thread): the kinematic groups correct the remapped velocities at their nodes so the
	// strain follows the constrained motion (KinematicContact::constrainRemap).
	template <class X>
	void afterRemap(const ContactStep<D, X>& s)
	{
		if (!hasKinematic()) return;
		s.exchange.oneThread([&] {
			for (size_t gi = 0; gi < groups.size(); ++gi)
				if (groups[gi].params.law == ContactLaw::Kinematic && !work[gi].skip) this->constrainRemap(gi, s);
		});
	}

private:
	std::vector<double>        partSums; // scratch of sumReactions
	std::vector<RigidPart<D>>  kept;     // scratch of reproject: the reactions before it

	// Some kinematic group has work this step (set by beforeTransfer).
	bool hasKinematic() const
	{
		for (size_t gi = 0; gi < groups.size(); ++gi)
			if (groups[gi].params.law == ContactLaw::Kinematic && gi < work.size() && !work[gi].skip) return true;
		return false;
	}
	// Force and torque of every part summed over the processes in a fixed order (one thread): the same bits on each.
	template <class X>
	void sumReactions(const X& exchange)
	{
		constexpr int n = D + (D == 2 ? 1 : 3); // force, torque
		partSums.resize(parts.size() * n);
		for (size_t p = 0; p < parts.size(); ++p)
			for (int k = 0; k < n; ++k) partSums[p * n + size_t(k)] = k < D ? parts[p].force[k] : parts[p].torque[k - D];
		exchange.sumInOrder(partSums.data(), int(partSums.size()));
		for (size_t p = 0; p < parts.size(); ++p)
			for (int k = 0; k < n; ++k) (k < D ? parts[p].force[k] : parts[p].torque[k - D]) = partSums[p * n + size_t(k)];
	}
};

} // namespace mpm
