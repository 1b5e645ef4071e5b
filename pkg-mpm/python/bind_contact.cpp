// Solver2D/3D: rigid parts, contact groups with their ContactParams (pkg-mpm/contact/ContactParams.hpp) and surface
// primitives for PTS contact (paper Sec. 2.3); the YADE adapters are py/yade_mpm/bodies.py and spheres.py.
#include "binding_common.hpp"

namespace mpm {
namespace {

template <int D>
struct ContactWrap {
	using S = Solver<D>;
	static std::string who(const char* what) { return solverName(D) + ": " + what; }

	// ---- rigid bodies for PTS contact (Sec. 2.3); the YADE adapter is py/yade_mpm/bodies.py
	using MatD = typename Dim<D>::Mat;
	using Spin = SpinOf<D>;
	static MatD toMat(const bp::object& o, const char* name)
	{
		np::ndarray a = asDoubleArray(o, name, D, D);
		MatD        m;
		auto*       p = reinterpret_cast<double*>(a.get_data());
		for (int i = 0; i < D; ++i)
			for (int j = 0; j < D; ++j) m(i, j) = p[i * D + j];
		return m;
	}
	static Spin toSpin(const bp::object& o, const char* name)
	{
		Spin w;
		if constexpr (D == 2) {
			w[0] = argReal(o, who(name) + " (ω_z)", "rad/s");
		} else {
			auto v = argReals(o, who(name), 3, "rad/s");
			for (int a = 0; a < 3; ++a) w[a] = v[a];
		}
		return w;
	}
	static bp::object fromSpin(const Spin& w)
	{
		if constexpr (D == 2) return bp::object(w[0]);
		else return bp::make_tuple(w[0], w[1], w[2]);
	}
	static int addRigidPart(S& s) { return s.contact.addPart(); }
	// A contact group over rigid parts with the contact parameters `params` (a ContactParams: the table's ranges,
	// and a fixed d0 at most one grid spacing), checked before anything is added.
	static int addContactGroup(S& s, bp::object parts, bp::object params)
	{
		bp::extract<const ContactParams&> px(params);
		if (!px.check()) throw InputError(who("addContactGroup: params") + " must be a ContactParams (got " + pyTypeName(params.ptr()) + ")");
		const ContactParams& prm = px();
		prm.validateFor(s.grid.spacing);
		PyObject* q = parts.ptr();
		if (!(PySequence_Check(q) && !PyUnicode_Check(q))) {
			PyErr_Clear();
			throw InputError(who("addContactGroup: parts") + " must be a sequence of rigid part indices (got " + pyTypeName(q) + ")");
		}
		std::vector<int> ps;
		for (long k = 0; k < bp::len(parts); ++k) ps.push_back(int(argInt(parts[k], who("addContactGroup: parts"), 0, 2147483647.0)));
		return s.contact.addGroup(prm, ps);
	}
	static ContactParams contactParams(S& s, int g) { return s.contact.group(g).params; }
	static int           numContactGroups(S& s) { return int(s.contact.groups.size()); }
	// d0 = 'initial': capture d0_p = d_p(0) of the first particle layer at the group's current pose (registration).
	static void captureContactD0(S& s, int g)
	{
		MPM_IF_MPI(s.dd.refuseAfterSplit("d0 = 'initial' (registering a body)");) // the capture needs every particle
		s.contact.captureInitialD0(g, s.P);
	}
	static void removeLastContactGroup(S& s) { s.contact.removeLastGroup(); }
	// Captured d0 [m] per stable particle id (NaN: the default half edge); empty unless d0 = 'initial'.
	static np::ndarray contactInitialD0(S& s, int g)
	{
		const auto& v   = s.contact.group(g).d0Initial;
		np::ndarray out = np::empty(bp::make_tuple(v.size()), np::dtype::get_builtin<double>());
		std::copy(v.begin(), v.end(), reinterpret_cast<double*>(out.get_data()));
		return out;
	}
	static void addContactBox(S& s, int g, int part, bp::object centre, bp::object rot, bp::object half)
	{
		s.contact.addBox(g, part, toVec<D>(centre, "box centre"), toMat(rot, "box rotation"), toVec<D>(half, "box half extents"));
	}
	static void addContactPlane(S& s, int g, int part, bp::object point, bp::object normal, bool twoSided)
	{
		s.contact.addPlane(g, part, toVec<D>(point, "plane point"), toVec<D>(normal, "plane normal"), twoSided);
	}
	static void addContactElement(S& s, int g, int part, bp::object verts)
	{
		np::ndarray a = asDoubleArray(verts, "element vertices", D, D);
		auto*       p = reinterpret_cast<double*>(a.get_data());
		typename Dim<D>::Vec v[D];
		for (int k = 0; k < D; ++k)
			for (int j = 0; j < D; ++j) v[k][j] = p[k * D + j];
		s.contact.addElement(g, part, v);
	}
	static void setRigidPartState(S& s, int part, bp::object pos, bp::object rot, bp::object vel, bp::object angVel)
	{
		s.contact.part(part).setState(toVec<D>(pos, "rigid body position"), toMat(rot, "rigid body orientation"), toVec<D>(vel, "rigid body velocity", "m/s"),
		                              toSpin(angVel, "rigid body angular velocity"));
	}
	// Mass [kg] / a moment of inertia [kg m²] of a rigid part (2D: per metre), in (0, inf]; inf = immovable along it.
	static Real massArg(const bp::object& o, const std::string& name, const char* unit)
	{
		bp::extract<double> x(o);
		if (!PyBool_Check(o.ptr()) && x.check() && std::isinf(x()) && x() > 0) return INFINITY;
		return argReal(o, name + " (or inf: immovable)", unit, 0, INFINITY, OO);
	}
	static Spin inertiaArg(const bp::object& o, const std::string& name)
	{
		const char* unit = D == 2 ? "kg m^2/m" : "kg m^2";
		Spin        I;
		if constexpr (D == 2) I[0] = massArg(o, name + " (I_z)", unit);
		else {
			PyObject* q = o.ptr();
			if (!(PySequence_Check(q) && !PyUnicode_Check(q) && PySequence_Size(q) == 3)) {
				PyErr_Clear();
				throw InputError(name + " must be a sequence of 3 principal moments [kg m^2] (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
			}
			for (int a = 0; a < 3; ++a) I[a] = massArg(o[a], name + "[" + std::to_string(a) + "]", unit);
		}
		return I;
	}
	// Mass and principal moments of inertia (axes of the part's rotation) for the stick step's body share.
	static void setRigidPartMass(S& s, int part, bp::object mass, bp::object inertia)
	{
		auto& q = s.contact.part(part);
		q.setMass(massArg(mass, who("setRigidPartMass: mass"), D == 2 ? "kg/m" : "kg"), inertiaArg(inertia, who("setRigidPartMass: inertia")));
	}
	static bp::tuple rigidPartMass(S& s, int part)
	{
		const auto& q = s.contact.part(part);
		return bp::make_tuple(q.mass, fromSpin(q.inertia));
	}
	static void addContactSphere(S& s, int g, int part, bp::object centre, double radius)
	{
		s.contact.addSphere(g, part, toVec<D>(centre, "sphere centre"), radius);
	}
	// ---- many DEM spheres at once (py/yade_mpm/spheres.py): one call per step, not one per body
	static std::vector<int> intList(const bp::object& o, const char* name)
	{
		np::ndarray a = np::from_object(o, np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		if (a.get_nd() != 1) throw InputError(std::string(name) + " must be a 1-D integer array");
		auto* p = reinterpret_cast<int64_t*>(a.get_data());
		return std::vector<int>(p, p + a.shape(0));
	}
	static void setContactGroupsEnabled(S& s, bp::object groups, bool on)
	{
		for (int g : intList(groups, "groups")) s.contact.setEnabled(g, on);
	}
	// Position, velocity and angular velocity of parts (orientation kept): pos, vel (n, D); angVel (n, 1) in 2D, (n, 3) in 3D.
	static void setRigidPartMotions(S& s, bp::object parts, bp::object pos, bp::object vel, bp::object angVel)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray x = asDoubleArray(pos, "positions", D, n), v = asDoubleArray(vel, "velocities", D, n),
		            w = asDoubleArray(angVel, "angular velocities", NS, n);
		auto *xp = reinterpret_cast<double*>(x.get_data()), *vp = reinterpret_cast<double*>(v.get_data()), *wp = reinterpret_cast<double*>(w.get_data());
		for (size_t k = 0; k < n; ++k) {
			auto& q = s.contact.part(ps[k]);
			typename Dim<D>::Vec c, u;
			Spin om;
			for (int a = 0; a < D; ++a) c[a] = xp[k * D + a], u[a] = vp[k * D + a];
			for (int a = 0; a < NS; ++a) om[a] = wp[k * NS + a];
			q.setState(c, q.R, u, om);
		}
	}
	// Masses (n,) and principal moments of inertia (n, 1 | 3) of parts, each in (0, inf] (inf: immovable along it).
	static void setRigidPartMasses(S& s, bp::object parts, bp::object mass, bp::object inertia)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray m = asDoubleArray(mass, "masses", 0, n), I = asDoubleArray(inertia, "moments of inertia", NS, n);
		auto *mp = reinterpret_cast<double*>(m.get_data()), *ip = reinterpret_cast<double*>(I.get_data());
		for (int pass = 0; pass < 2; ++pass) // every entry checked before any is changed
			for (size_t k = 0; k < n; ++k) {
				Spin J;
				for (int a = 0; a < NS; ++a) J[a] = ip[k * NS + a];
				RigidPart<D> probe;                         // pass 0: validate on a copy
				auto&        q = s.contact.part(ps[k]);     // checks the index
				(pass ? q : probe).setMass(mp[k], J);
			}
	}
	// Reaction forces (n, D) and torques (n, 1 | 3) of parts from the last step.
	static bp::tuple rigidPartReactions(S& s, bp::object parts)
	{
		const auto  ps = intList(parts, "parts");
		const size_t n = ps.size();
		constexpr int NS = D == 2 ? 1 : 3;
		np::ndarray f = np::zeros(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		np::ndarray m = np::zeros(bp::make_tuple(n, NS), np::dtype::get_builtin<double>());
		auto *fp = reinterpret_cast<double*>(f.get_data()), *mp = reinterpret_cast<double*>(m.get_data());
		for (size_t k = 0; k < n; ++k) {
			const auto& q = s.contact.part(ps[k]);
			for (int a = 0; a < D; ++a) fp[k * D + a] = q.force[a];
			for (int a = 0; a < NS; ++a) mp[k * NS + a] = q.torque[a];
		}
		return bp::make_tuple(f, m);
	}
	static bp::tuple rigidPartForce(S& s, int part) { return fromVec<D>(s.contact.part(part).force); }
	static bp::object rigidPartTorque(S& s, int part) { return fromSpin(s.contact.part(part).torque); }
	// Signed distance, outward normal and owning part of a contact group at a point (for tests and inspection).
	static bp::tuple contactQuery(S& s, int g, bp::object point)
	{
		auto& grp = s.contact.group(g);
		grp.update(s.contact.parts);
		auto h = grp.query(toVec<D>(point, "point"));
		return bp::make_tuple(h.d, fromVec<D>(h.n), h.part);
	}
	static bool contactGroupClosed(S& s, int g)
	{
		auto& grp = s.contact.group(g);
		grp.update(s.contact.parts);
		return grp.closed;
	}
	// Contact force each node received from the last group processed in the last step, (nodes, D) [N].
	static np::ndarray contactNodeForces(S& s)
	{
		size_t      n   = s.grid.size();
		np::ndarray out = np::zeros(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		auto*       o   = reinterpret_cast<double*>(out.get_data());
		if (s.contact.nodeArr.size() == n)
			for (size_t i = 0; i < n; ++i)
				for (int a = 0; a < D; ++a) o[i * D + a] = s.contact.nodeArr.force[a][i];
		return out;
	}
	static bool contactActive(S& s) { return s.contact.active(); }
	// The kinematic law's warm start of group g (checkpoints): (particle ids, impulses (n, D) [N s], Δt of their step [s]).
	static bp::tuple kinematicWarmStart(S& s, int g)
	{
		s.contact.group(g); // refuses a group that does not exist
		const bool  has = size_t(g) < s.contact.warm.size();
		const auto  n   = has ? s.contact.warm[size_t(g)].imp.size() : 0;
		np::ndarray ids = np::empty(bp::make_tuple(n), np::dtype::get_builtin<int64_t>());
		np::ndarray lam = np::empty(bp::make_tuple(n, D), np::dtype::get_builtin<double>());
		auto*       pi  = reinterpret_cast<int64_t*>(ids.get_data());
		auto*       pl  = reinterpret_cast<double*>(lam.get_data());
		for (size_t k = 0; k < n; ++k) {
			const auto& w = s.contact.warm[size_t(g)].imp[k];
			pi[k]         = w.id;
			for (int a = 0; a < D; ++a) pl[k * D + a] = w.lam[a];
		}
		return bp::make_tuple(ids, lam, has ? s.contact.warm[size_t(g)].dt : 0.0);
	}
	static void setKinematicWarmStart(S& s, int g, bp::object ids, bp::object lam, double dt)
	{
		s.contact.group(g); // refuses a group that does not exist
		np::ndarray i = np::from_object(ids, np::dtype::get_builtin<int64_t>(), np::ndarray::C_CONTIGUOUS);
		if (i.get_nd() != 1) throw InputError("warm-start ids must be a 1-D integer array");
		const size_t n = size_t(i.shape(0));
		np::ndarray  l = asDoubleArray(lam, "warm-start impulses", D, n);
		if (!(dt >= 0 && std::isfinite(dt))) throw InputError("warm-start dt = " + fmtNum(dt) + " s must be finite and >= 0");
		auto* pi = reinterpret_cast<const int64_t*>(i.get_data());
		auto* pl = reinterpret_cast<const double*>(l.get_data());
		for (size_t k = 1; k < n; ++k)
			if (!(pi[k - 1] < pi[k])) throw InputError("warm-start ids must be strictly ascending");
		auto& w = s.contact.warm;
		if (w.size() < s.contact.groups.size()) w.resize(s.contact.groups.size());
		auto& wg = w[size_t(g)];
		wg.imp.resize(n), wg.dt = dt;
		for (size_t k = 0; k < n; ++k) {
			wg.imp[k].id = pi[k];
			for (int a = 0; a < D; ++a) wg.imp[k].lam[a] = pl[k * D + a];
		}
	}

	static void expose(SolverClass<D>& cls, const char* name)
	{
		cls.def("_addRigidPart", &addRigidPart, "new rigid part (one YADE body or clump); returns its index")
		        .def("_addContactGroup", &addContactGroup, (bp::arg("parts"), bp::arg("params")),
		             "contact group over rigid parts with a ContactParams (μ, c, χ, d0, autoD0, initialD0; d0 at most one grid "
		             "spacing); returns its index. With initialD0, call captureContactD0 at registration")
		        .def("_contactParams", &contactParams, bp::arg("group"), "copy of the ContactParams of a contact group")
		        .add_property("_numContactGroups", &numContactGroups, "number of contact groups")
		        .def("_captureContactD0", &captureContactD0, (bp::arg("group")),
		             "d0 = 'initial': d0_p := initial distance of the first particle layer next to the group at its current pose")
		        .def("_removeLastContactGroup", &removeLastContactGroup,
		             "undo the last addContactGroup and its rigid parts (a registration refused half-way)")
		        .def("_contactInitialD0", &contactInitialD0, (bp::arg("group")),
		             "captured d0 [m] per particle id (NaN = default half edge); empty unless d0 = 'initial'")
		        .def("_addContactBox", &addContactBox, (bp::arg("group"), bp::arg("part"), bp::arg("centre"), bp::arg("rotation"), bp::arg("half")))
		        .def("_addContactPlane", &addContactPlane, (bp::arg("group"), bp::arg("part"), bp::arg("point"), bp::arg("normal"), bp::arg("twoSided")))
		        .def("_addContactElement", &addContactElement, (bp::arg("group"), bp::arg("part"), bp::arg("vertices")))
		        .def("_setRigidPartState", &setRigidPartState, (bp::arg("part"), bp::arg("pos"), bp::arg("rot"), bp::arg("vel"), bp::arg("angVel")))
		        .def("_addContactSphere", &addContactSphere, (bp::arg("group"), bp::arg("part"), bp::arg("centre"), bp::arg("radius")),
		             "sphere (3D) / circle (2D) of radius [m] at centre (part frame) in a contact group")
		        .def("_setContactGroupsEnabled", &setContactGroupsEnabled, (bp::arg("groups"), bp::arg("enabled")),
		             "switch contact groups on/off (off: skipped entirely)")
		        .def("_setRigidPartMotions", &setRigidPartMotions, (bp::arg("parts"), bp::arg("pos"), bp::arg("vel"), bp::arg("angVel")),
		             "positions, velocities, angular velocities of many parts (orientation unchanged)")
		        .def("_setRigidPartMass", &setRigidPartMass, (bp::arg("part"), bp::arg("mass"), bp::arg("inertia")),
		             "mass [kg] (2D: kg/m) and principal moments of inertia about the centre along the part's axes [kg m^2] (2D: I_z, "
		             "kg m^2/m) of a part, each in (0, inf]; inf (the default) = immovable along it (the paper's stick step). For a free "
		             "part every contact node sticks to the part's motion after the step, from its momentum balance (doc/reference/contact.md)")
		        .def("_rigidPartMass", &rigidPartMass, bp::arg("part"), "(mass, inertia) of a part as set by setRigidPartMass")
		        .def("_setRigidPartMasses", &setRigidPartMasses, (bp::arg("parts"), bp::arg("mass"), bp::arg("inertia")),
		             "masses (n,) and principal moments of inertia (n, 1|3) of many parts, as setRigidPartMass")
		        .def("_rigidPartReactions", &rigidPartReactions, bp::arg("parts"), "(forces (n, D), torques (n, 1|3)) of parts")
		        .def("_rigidPartForce", &rigidPartForce, bp::arg("part"))
		        .def("_rigidPartTorque", &rigidPartTorque, bp::arg("part"))
		        .def("_contactQuery", &contactQuery, (bp::arg("group"), bp::arg("point")))
		        .def("_contactGroupClosed", &contactGroupClosed, bp::arg("group"))
		        .def("_contactNodeForces", &contactNodeForces)
		        .def("_kinematicWarmStart", &kinematicWarmStart, bp::arg("group"),
		             "(ids, impulses (n, D) [N s], dt [s]): the kinematic law's start of group g's next step (checkpoints)")
		        .def("_setKinematicWarmStart", &setKinematicWarmStart, (bp::arg("group"), bp::arg("ids"), bp::arg("impulses"), bp::arg("dt")))
		        .add_property("_contactActive", &contactActive);
	}
};
} // namespace

MPM_EXPOSE_SOLVER_PART(exposeContact, ContactWrap)
} // namespace mpm
