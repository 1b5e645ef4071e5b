// Boost.Python side of the one-declaration parameter tables (pkg-mpm/core/ParamTable.hpp).
// For a struct S with MPM_PARAMS(...), exposeParams<S>(cls, aliases) adds to the class:
//   - one property per parameter, docstring from the table (doc, symbol, unit, range, default, Eq.),
//     setter that refuses a wrong type or an out-of-range value with a ValueError naming the
//     parameter, its unit and its range (None unsets a required parameter);
//   - a keyword constructor S(name=value, ...) that refuses unknown names and validates;
//   - toDict() (primary names, unset → None) and the static fromDict(d) (aliases accepted), exact
//     round trip: S.fromDict(s.toDict()).toDict() == s.toDict();
//   - the static paramTable(): list of dicts (name, type, default, unit, lo, hi, ends, symbol, doc, eq, gate).
// The class must be held by std::shared_ptr<S> and have a validate() method (whole-object checks).
#pragma once
#include "../core/ParamTable.hpp"
#include <boost/mpl/vector.hpp>
#include <boost/python.hpp>
#include <boost/python/raw_function.hpp>
#include <map>

namespace mpm {
namespace bp = boost::python;

// Python value → C++ parameter value, or an InputError naming `who` (e.g. "DpGkMat.young").
inline std::string pyTypeName(PyObject* o) { return Py_TYPE(o)->tp_name; }
inline std::string pyRepr(const bp::object& o)
{
	std::string r = bp::extract<std::string>(bp::str(o));
	return r.size() > 40 ? r.substr(0, 37) + "..." : r;
}

inline Real pyToReal(const bp::object& o, const std::string& who, const ParamInfo& p)
{
	PyObject* q = o.ptr();
	if (PyBool_Check(q) || PyUnicode_Check(q) || PyBytes_Check(q) || !(PyFloat_Check(q) || PyIndex_Check(q) || PyNumber_Check(q)))
		throw InputError(who + " must be a number [" + p.unit + "] in " + p.rangeText() + " (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
	double v = PyFloat_AsDouble(q);
	if (v == -1.0 && PyErr_Occurred()) {
		PyErr_Clear();
		throw InputError(who + " must be a number [" + p.unit + "] in " + p.rangeText() + " (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
	}
	return v;
}

template <class T>
T pyToParam(const bp::object& o, const std::string& who, const ParamInfo& p)
{
	PyObject* q = o.ptr();
	if constexpr (std::is_enum_v<T>) { // named option: one of its words; the old integer codes are refused
		const bool isStr = PyUnicode_Check(q);
		const int  k     = isStr ? p.wordIndex(bp::extract<std::string>(o)) : -1;
		if (k >= 0) return T(k);
		throw InputError(who + " must be one of " + p.wordsText() + " (got " + pyTypeName(q) + " " + pyRepr(o) + ")"
		                 + (isStr ? "" : "; the integer codes were replaced by these words"));
	} else if constexpr (std::is_same_v<T, bool>) {
		if (PyBool_Check(q)) return q == Py_True;
		if (PyIndex_Check(q) && !PyFloat_Check(q)) {
			long v = PyLong_AsLong(q);
			if (!PyErr_Occurred() && (v == 0 || v == 1)) return v == 1;
			PyErr_Clear();
		}
		throw InputError(who + " must be True or False (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
	} else if constexpr (std::is_integral_v<T>) {
		if (PyBool_Check(q) || !PyIndex_Check(q)) throw InputError(who + " must be an integer in " + p.rangeText() + " (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
		long long v = PyLong_AsLongLong(q);
		if (PyErr_Occurred()) {
			PyErr_Clear();
			throw InputError(who + " = " + pyRepr(o) + " is outside the allowed range " + p.rangeText());
		}
		if (!p.inRange(Real(v))) throw InputError(who + " = " + std::to_string(v) + " [" + p.unit + "] is outside the allowed range " + p.rangeText());
		return T(v);
	} else if constexpr (std::is_floating_point_v<T>) {
		if (q == Py_None && p.required()) return T(NAN); // unset
		Real v = pyToReal(o, who, p);
		if (!p.inRange(v)) throw InputError(who + " = " + ParamInfo::num(v) + " [" + p.unit + "] is outside the allowed range " + p.rangeText());
		return T(v);
	} else { // fixed-size Eigen vector: every component in range
		constexpr int N = T::RowsAtCompileTime;
		const Py_ssize_t n = PySequence_Check(q) && !PyUnicode_Check(q) ? PySequence_Size(q) : -1;
		if (n != N) {
			PyErr_Clear();
			throw InputError(who + " must be a sequence of " + std::to_string(N) + " numbers [" + p.unit + "] (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
		}
		T v;
		for (int a = 0; a < N; ++a) {
			v[a] = pyToReal(o[a], who + "[" + std::to_string(a) + "]", p);
			if (!p.inRange(v[a]))
				throw InputError(who + "[" + std::to_string(a) + "] = " + ParamInfo::num(v[a]) + " [" + p.unit + "] is outside the allowed range " + p.rangeText());
		}
		return v;
	}
}

template <class T>
bp::object paramToPy(const T& v)
{
	if constexpr (std::is_enum_v<T>) return bp::str(paramWord(v));
	else if constexpr (std::is_same_v<T, bool>) return bp::object(bool(v));
	else if constexpr (std::is_integral_v<T>) return bp::object(long(v));
	else if constexpr (std::is_floating_point_v<T>) return std::isnan(v) ? bp::object() : bp::object(double(v));
	else {
		bp::list l;
		for (int a = 0; a < T::RowsAtCompileTime; ++a) l.append(double(v[a]));
		return bp::tuple(l);
	}
}

template <class S>
struct ParamBinding {
	static std::string& clsName()
	{
		static std::string n;
		return n;
	}
	static std::map<std::string, std::string>& aliases()
	{
		static std::map<std::string, std::string> a;
		return a;
	}
	static std::string knownNames()
	{
		std::string k;
		S::forEachMember([&](const ParamInfo& p, auto) { k += (k.empty() ? "" : ", ") + std::string(p.name); });
		for (auto& [a, t] : aliases()) k += ", " + a + " (alias of " + t + ")";
		return k;
	}
	// Sets parameter `name` (or an alias) of s from a Python value; false if no such parameter.
	static bool set(S& s, const std::string& name, const bp::object& v)
	{
		auto        al  = aliases().find(name);
		std::string key = al == aliases().end() ? name : al->second;
		bool        done = false;
		S::forEachMember([&](const ParamInfo& p, auto mp) {
			using T = std::decay_t<decltype(s.*mp)>;
			if (!done && key == p.name) s.*mp = pyToParam<T>(v, clsName() + "." + name, p), done = true;
		});
		return done;
	}
	static void setFromDict(S& s, const bp::dict& d)
	{
		bp::list keys = d.keys();
		for (long i = 0; i < bp::len(keys); ++i) {
			bp::object k = keys[i];
			if (!PyUnicode_Check(k.ptr())) throw InputError(clsName() + ": parameter names must be strings (got " + pyRepr(k) + ")");
			std::string name = bp::extract<std::string>(k);
			if (!set(s, name, d[k])) { // TypeError, as Python does for an unexpected keyword
				PyErr_SetString(PyExc_TypeError, (clsName() + ": unknown parameter '" + name + "'; known: " + knownNames()).c_str());
				bp::throw_error_already_set();
			}
		}
		s.validate();
	}
	static bp::dict toDict(const S& s)
	{
		bp::dict d;
		S::forEachMember([&](const ParamInfo& p, auto mp) { d[p.name] = paramToPy(s.*mp); });
		return d;
	}
	static std::shared_ptr<S> fromDict(bp::object d)
	{
		if (!PyDict_Check(d.ptr())) throw InputError(clsName() + ".fromDict: expected a dict (got " + pyTypeName(d.ptr()) + ")");
		auto s = std::make_shared<S>();
		setFromDict(*s, bp::dict(d));
		return s;
	}
	static bp::list table()
	{
		bp::list l;
		S::forEachMember([&](const ParamInfo& p, auto) {
			bp::dict e;
			e["name"] = p.name, e["type"] = p.type, e["default"] = p.required() ? bp::object() : bp::object(p.def);
			if (p.isChoice()) {
				bp::list w;
				for (const auto& x : p.words()) w.append(x);
				e["choices"] = w, e["default"] = p.words()[size_t(p.def)];
			}
			e["unit"] = p.unit, e["lo"] = p.lo, e["hi"] = p.hi, e["loOpen"] = p.loOpen(), e["hiOpen"] = p.hiOpen();
			e["symbol"] = p.symbol, e["doc"] = p.doc, e["eq"] = p.eq, e["gate"] = p.gate, e["describe"] = p.describe();
			l.append(e);
		});
		return l;
	}
	// S(**kw): with keywords, every name must be a parameter and the result is validated.
	static bp::object kwInit(bp::tuple args, bp::dict kw)
	{
		bp::object self = args[0];
		if (bp::len(args) > 1) throw InputError(clsName() + " takes keyword arguments only (name=value); parameters: " + knownNames());
		self.attr("_init")(); // the C++ default constructor
		if (bp::len(kw) > 0) setFromDict(bp::extract<S&>(self), kw);
		return bp::object();
	}
	static std::string classDoc(const std::string& head)
	{
		std::string d = head + "\n\nKeyword constructor " + clsName() + "(name=value, ...): unknown names are refused and the "
		                "result is validated. toDict() / " + clsName() + ".fromDict(d) round-trip the parameters.\n\nParameters:\n";
		S::forEachMember([&](const ParamInfo& p, auto) { d += "  " + std::string(p.name) + ": " + p.describe() + "\n"; });
		for (auto& [a, t] : aliases()) d += "  " + a + ": alias of " + t + "\n";
		return d;
	}

	// Call first: the class name used in messages and the aliases (alias → parameter name).
	static void declare(const std::string& name, std::map<std::string, std::string> alias = {})
	{
		clsName() = name;
		aliases() = std::move(alias);
	}
	// cls: bp::class_<S, std::shared_ptr<S>, ...>(name, classDoc(head).c_str(), bp::no_init), after declare().
	template <class Cls>
	static void expose(Cls& cls)
	{
		cls.def("_init", bp::make_constructor(+[] { return std::make_shared<S>(); }));
		cls.def("__init__", bp::raw_function(&kwInit));
		cls.def("toDict", &toDict, "Parameters as a dict {name: value} (unset → None), for checkpoints.");
		cls.def("fromDict", &fromDict, "New validated object from a dict made by toDict() (aliases accepted).");
		cls.staticmethod("fromDict");
		cls.def("paramTable", &table, "The parameter declarations: one dict per parameter.");
		cls.staticmethod("paramTable");
		cls.def("validate", &S::validate, "Raise ValueError naming the first parameter outside its range (or conditions that tie parameters).");
		exposeProperties(cls);
		for (auto& [a, t] : aliases()) {
			std::string target = t, alias = a;
			auto get = [target](bp::object self) { return self.attr(target.c_str()); };
			auto put = [target](bp::object self, bp::object v) { self.attr(target.c_str()) = v; };
			cls.add_property(alias.c_str(), bp::make_function(get, bp::default_call_policies(), boost::mpl::vector<bp::object, bp::object>()),
			                 bp::make_function(put, bp::default_call_policies(), boost::mpl::vector<void, bp::object, bp::object>()),
			                 ("alias of " + target).c_str());
		}
	}
	// One checked property per parameter (also for classes without the keyword constructor, e.g. the solver).
	template <class Cls>
	static void exposeProperties(Cls& cls)
	{
		S::forEachMember([&](const ParamInfo& p, auto mp) {
			using T   = std::decay_t<decltype(std::declval<S&>().*mp)>;
			auto get  = [mp](const S& s) { return paramToPy(s.*mp); };
			auto put  = [mp, p](S& s, bp::object v) { s.*mp = pyToParam<T>(v, clsName() + "." + p.name, p); };
			cls.add_property(p.name, bp::make_function(get, bp::default_call_policies(), boost::mpl::vector<bp::object, const S&>()),
			                 bp::make_function(put, bp::default_call_policies(), boost::mpl::vector<void, S&, bp::object>()), p.describe().c_str());
		});
	}
};

} // namespace mpm

namespace mpm {
// Named conversion of one function argument (same checks and messages as the parameter setters):
// who = "Solver2D.run: steps", range [lo, hi] with `ends` as in the tables.
inline Real argReal(const bp::object& o, const std::string& who, const char* unit, Real lo = -INFINITY, Real hi = INFINITY, int ends = OO)
{
	const ParamInfo p { who.c_str(), "float", 0, unit, lo, hi, ends, "", "", "", "" };
	return pyToParam<Real>(o, who, p);
}
inline long long argInt(const bp::object& o, const std::string& who, Real lo, Real hi)
{
	const ParamInfo p { who.c_str(), "int", 0, "-", lo, hi, CC, "", "", "", "" };
	return pyToParam<long long>(o, who, p);
}
inline bool argBool(const bp::object& o, const std::string& who)
{
	const ParamInfo p { who.c_str(), "bool", 0, "-", 0, 1, CC, "", "", "", "" };
	return pyToParam<bool>(o, who, p);
}
inline std::string argStr(const bp::object& o, const std::string& who)
{
	if (!PyUnicode_Check(o.ptr())) throw InputError(who + " must be a string (got " + pyTypeName(o.ptr()) + " " + pyRepr(o) + ")");
	return bp::extract<std::string>(o);
}
// A sequence of exactly n numbers in range, as doubles.
inline std::vector<Real> argReals(const bp::object& o, const std::string& who, int n, const char* unit, Real lo = -INFINITY, Real hi = INFINITY,
                                  int ends = OO)
{
	PyObject*        q = o.ptr();
	const Py_ssize_t len = PySequence_Check(q) && !PyUnicode_Check(q) ? PySequence_Size(q) : -1;
	if (len != n) {
		PyErr_Clear();
		throw InputError(who + " must be a sequence of " + std::to_string(n) + " numbers [" + unit + "] (got " + pyTypeName(q) + " " + pyRepr(o) + ")");
	}
	std::vector<Real> v(n);
	for (int k = 0; k < n; ++k) v[k] = argReal(o[k], who + "[" + std::to_string(k) + "]", unit, lo, hi, ends);
	return v;
}
} // namespace mpm
