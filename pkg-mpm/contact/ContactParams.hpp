// The contact parameters of one contact group (paper Sec. 2.3, Eqs. 23–26), each declared once (columns:
// ParamTable.hpp). The fields, the range checks, the Python class ym.ContactParams (properties with unit
// and range, keyword constructor, toDict/fromDict for checkpoints), the registration keywords of
// ym.RigidBodies/ym.DemSpheres and the tables of doc/contact.md all come from this list.
#pragma once
#include "../core/ParamTable.hpp"

namespace mpm {
// How the contact keeps particles out of a rigid body (doc/contact.md, "Contact laws").
enum class ContactLaw : int {
	Kinematic = 0, // impulses at the contacting particles: no approach, residual overlap closed in one step, Coulomb +
	               // cohesion as an impulse limit; the Δt → 0 limit of Eq. 23 reached at any Δt (KinematicContact.hpp; default)
	Penalty   = 1  // Eq. 23 exactly as printed: f = (1 − χ) κ_p (d0 − d_p) n_p, κ_p = 2 m_p/Δt² (the paper's, a named option)
};
MPM_CHOICES(ContactLaw, "kinematic|penalty")
} // namespace mpm

// X(type, name, default, unit, lo, hi, ends, symbol, doc, equation, gate). Why chi = ½, autoD0 and initialD0:
// doc/developer/core_notes.md.
#define MPM_CONTACT_PARAMS(X)                                                                                                     \
	X(ContactLaw, law, ContactLaw::Kinematic, "-", 0, 1, CC, "",                                                               \
	  "'kinematic' (default): no-penetration impulses at the contacting particles (projected Gauss–Seidel), the Δt → 0 "    \
	  "limit of Eq. 23 at any Δt; 'penalty': Eq. 23 as printed, κ_p = 2 m_p/Δt² (the paper's; a contact compliance that "   \
	  "grows with Δt²)", "Eqs. 23–26", "")                                                                                       \
	X(Real, mu, 0, "-", 0, INFINITY, CO, "μ_con",                                                                                \
	  "Coulomb friction coefficient of the contact (ym.RigidBodies/DemSpheres.add without mu: tan(frictionAngle) of the "     \
	  "body's YADE FrictMat)", "Eq. 24", "")                                                                                     \
	X(Real, cohesion, 0, "Pa", 0, INFINITY, CO, "c_con", "contact cohesion (tangential capacity per contact area)", "Eq. 24", "") \
	X(Real, chi, 0.5, "-", 0, 1, CO, "χ",                                                                                        \
	  "residual penetration factor of the penalty law: the normal force is (1 − χ) κ_p (d0 − d_p), κ_p = 2 m_p/Δt² "             \
	  "(unused by the kinematic law)", "Eq. 23", "")               \
	X(Real, d0, 0, "m", 0, INFINITY, CO, "d0",                                                                                   \
	  "detection distance when autoD0 is off; at most one grid spacing (checked when the group is added)", "Eq. 23", "")       \
	X(bool, autoD0, true, "-", 0, 1, CC, "", "d0 = ½ V_p^{1/D}, half the particle's own edge (registration keyword d0=None)",  \
	  "Eq. 23", "")                                                                                                              \
	X(bool, initialD0, false, "-", 0, 1, CC, "",                                                                                 \
	  "the first particle layer next to the body at registration gets d0 = its initial distance (registration keyword "         \
	  "d0='initial')", "Eq. 23, text after Eq. 26", "")

namespace mpm {

struct ContactParams {
	MPM_PARAMS(ContactParams, NoParams, MPM_CONTACT_PARAMS) // law, μ, c, χ, d0, autoD0, initialD0

	// The table's ranges. d0 beyond one cell is refused where the grid is known (validateFor).
	void validate() const { validateParams(); }
	// With the grid spacing l [m]: a fixed d0 is at most l (the contact acts at the particles' surface; a
	// larger detection distance pushes material that is cells away from the body).
	void validateFor(Real l) const
	{
		validate();
		if (!autoD0 && d0 > l)
			throw InputError("d0 = " + ParamInfo::num(d0) + " [m] is outside the allowed range [0, " + ParamInfo::num(l)
			                 + "] (at most one grid spacing; None = half the particle edge)");
	}
};
static_assert(std::is_trivially_copyable_v<ContactParams>, "contact parameters must stay plain data");

} // namespace mpm
