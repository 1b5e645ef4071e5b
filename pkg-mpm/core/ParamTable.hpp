// One declaration per parameter (the idea of YADE's YADE_CLASS_BASE_DOC_ATTRS).
//
// A parameter list is an X-macro: one line per parameter with
//   X(type, name, default, unit, lo, hi, ends, symbol, doc, equation, gate)
// - type    Real, int or bool (the binding layer also accepts Dim<D>::Vec, range per component), or a named
//           option: an enum with MPM_CHOICES(Enum, "word0|word1|…") (Python sees and sets the words only;
//           default = an enumerator; lo, hi = 0, count − 1)
// - default the value a new object gets; MPM_REQUIRED = no default, must be set (NaN inside)
// - lo, hi  allowed range, `ends` one of OO, OC, CO, CC (open/closed lower, upper end)
// - gate    name of a bool parameter of the same object that switches this one on ("" = always);
//           a gated parameter is only range-checked (and required) while its gate is true
// From the list, MPM_PARAMS(Struct, LIST) generates inside the struct:
//   the plain fields (hot loops read them directly, no lookups), a static table of ParamInfo,
//   forEachMember(f) visiting (info, member pointer) and validateParams() (range + required).
// The binding layer (python/param_binding.hpp) generates Python properties with docstrings, typed
// setters, keyword constructors and toDict/fromDict from the same table.
#pragma once
#include "MpmTypes.hpp"
#include <limits>
#include <vector>

namespace mpm {

enum ParamEnds : int { OO = 0, OC = 1, CO = 2, CC = 3 }; // (lo, hi), (lo, hi], [lo, hi), [lo, hi]

struct ParamInfo {
	const char* name;
	const char* type; // "float", "int", "bool", "vector"
	Real        def;  // NaN = required
	const char* unit;
	Real        lo, hi;
	int         ends;
	const char* symbol;
	const char* doc;
	const char* eq;   // paper equation numbers, e.g. "Eq. 34" ("" if none)
	const char* gate; // bool parameter switching this one on ("" = always on)
	const char* choices = ""; // named option: "word0|word1|…" (word k = enumerator k), "" otherwise

	bool loOpen() const { return ends == OO || ends == OC; }
	bool hiOpen() const { return ends == OO || ends == CO; }
	bool required() const { return std::isnan(def); }
	bool isChoice() const { return *choices != 0; }
	// The words of a named option, in enumerator order.
	std::vector<std::string> words() const
	{
		std::vector<std::string> w(1);
		for (const char* c = choices; *c; ++c)
			if (*c == '|') w.emplace_back();
			else w.back() += *c;
		return w;
	}
	// "'particle', 'cube' or 'cell'"
	std::string wordsText() const
	{
		const auto  w = words();
		std::string t;
		for (size_t k = 0; k < w.size(); ++k) t += (k == 0 ? "" : k + 1 == w.size() ? " or " : ", ") + ("'" + w[k] + "'");
		return t;
	}
	int wordIndex(const std::string& word) const
	{
		const auto w = words();
		for (size_t k = 0; k < w.size(); ++k)
			if (w[k] == word) return int(k);
		return -1;
	}
	static std::string num(Real x)
	{
		if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
		char b[32];
		if (x == std::floor(x) && std::abs(x) < 1e15 && std::abs(x) >= 1e6) snprintf(b, sizeof(b), "%.0f", x); // counts: 16777216, not 1.67772e+07
		else snprintf(b, sizeof(b), "%g", x);
		return b;
	}
	// "(0, inf)", "[0, 1]", ...
	std::string rangeText() const { return std::string(loOpen() ? "(" : "[") + num(lo) + ", " + num(hi) + (hiOpen() ? ")" : "]"); }
	// NaN fails every comparison; ±inf passes only an infinite end the range closes on ("[1, inf]": inf = "never").
	bool inRange(Real v) const { return (loOpen() ? v > lo : v >= lo) && (hiOpen() ? v < hi : v <= hi); }
	// Throws InputError naming the parameter, the value, the unit and the allowed range.
	void check(Real v) const
	{
		if (inRange(v)) return;
		if (std::isnan(v) && required())
			throw InputError(std::string(name) + " [" + unit + "] is required (no default); allowed range " + rangeText()
			                 + (*gate ? std::string(" (needed because ") + gate + " is on)" : ""));
		throw InputError(std::string(name) + " = " + num(v) + " [" + unit + "] is outside the allowed range " + rangeText());
	}
	// One-line description used for docstrings: "E: Young's modulus [Pa], range (0, inf), required. Eqs. 27–28."
	std::string describe() const
	{
		std::string s = (*symbol ? std::string(symbol) + ": " : "") + doc + " [" + unit + "], "
		                + (std::string(type) == "bool" ? std::string("True or False") : isChoice() ? "one of " + wordsText() : "range " + rangeText());
		if (required()) s += ", required" + (*gate ? std::string(" when ") + gate + " is on" : "");
		else if (std::string(type) == "bool") s += std::string(", default ") + (def != 0 ? "True" : "False");
		else if (isChoice()) s += ", default '" + words()[size_t(def)] + "'";
		else s += ", default " + num(def);
		if (*eq) s += std::string(". ") + eq;
		return s + ".";
	}
};

// Named options: MPM_CHOICES(Enum, "word0|word1|…") after `enum class Enum : int { … }` (enumerators 0, 1, …)
// declares the words; a parameter of type Enum is then exposed to Python as these words.
template <class T>
struct ParamChoices {
	static constexpr const char* words = "";
};
#define MPM_CHOICES(Enum, WORDS)                       \
	template <>                                        \
	struct ParamChoices<Enum> {                        \
		static constexpr const char* words = WORDS;    \
	};

// The word of a named option's value ("particle").
template <class E>
std::string paramWord(E e)
{
	ParamInfo p {};
	p.choices = ParamChoices<E>::words;
	const auto w = p.words();
	return size_t(e) < w.size() ? w[size_t(e)] : std::to_string(int(e));
}

template <class T>
constexpr const char* paramTypeName()
{
	if constexpr (std::is_enum_v<T>) return "choice";
	else if constexpr (std::is_same_v<T, bool>) return "bool";
	else if constexpr (std::is_integral_v<T>) return "int";
	else if constexpr (std::is_floating_point_v<T>) return "float";
	else return "vector";
}

// Value of a parameter as a Real, for range checks (vectors are checked per component by the caller).
template <class T>
Real paramAsReal(const T& v)
{
	if constexpr (std::is_arithmetic_v<T>) return Real(v);
	else if constexpr (std::is_enum_v<T>) return Real(int(v));
	else return 0;
}

// Initial value of a field from its declared default (vectors: every component; named options: the enumerator).
template <class T>
T paramDefault(Real def)
{
	if constexpr (std::is_enum_v<T>) return T(int(def));
	else if constexpr (std::is_arithmetic_v<T>) return T(def);
	else return T::Constant(def);
}

#define MPM_REQUIRED std::numeric_limits<double>::quiet_NaN()
#define MPM_PARAM_FIELD_(T, name, def, ...) T name = ::mpm::paramDefault<T>(::mpm::paramAsReal(def));
#define MPM_PARAM_INFO_(T, name, def, unit, lo, hi, ends, sym, doc, eq, gate)                                                          \
	::mpm::ParamInfo { #name, ::mpm::paramTypeName<T>(), ::mpm::paramAsReal(def), unit, ::mpm::Real(lo), ::mpm::Real(hi), ends, sym, doc, eq, gate, \
		           ::mpm::ParamChoices<T>::words },
#define MPM_PARAM_VISIT_(T, name, ...) f(info[i++], &Self_::name);

// Inside a struct: fields, table, member visitor, range validation. Base = a struct with
// MPM_PARAMS (its parameters come first) or ::mpm::NoParams.
#define MPM_PARAMS(Self, Base, LIST)                                                                \
	LIST(MPM_PARAM_FIELD_)                                                                          \
	static const std::vector<::mpm::ParamInfo>& ownParams()                                         \
	{                                                                                               \
		static const std::vector<::mpm::ParamInfo> v { LIST(MPM_PARAM_INFO_) };                     \
		return v;                                                                                   \
	}                                                                                               \
	template <class F>                                                                              \
	static void forEachMember(F&& f)                                                                \
	{                                                                                               \
		Base::forEachMember(f);                                                                     \
		using Self_      = Self;                                                                    \
		const auto& info = ownParams();                                                             \
		size_t      i    = 0;                                                                       \
		LIST(MPM_PARAM_VISIT_)                                                                      \
	}                                                                                               \
	static std::vector<::mpm::ParamInfo> params()                                                   \
	{                                                                                               \
		std::vector<::mpm::ParamInfo> v;                                                            \
		forEachMember([&](const ::mpm::ParamInfo& p, auto) { v.push_back(p); });                    \
		return v;                                                                                   \
	}                                                                                               \
	/* every parameter whose gate is on lies in its declared range (required ones are set) */      \
	void validateParams() const { ::mpm::validateParamsOf(*this); }

struct NoParams {
	template <class F>
	static void forEachMember(F&&) { }
};

// Value of the bool parameter `gate` of obj (true if gate is "").
template <class S>
bool paramGateOn(const S& obj, const char* gate)
{
	if (!*gate) return true;
	bool on = false, found = false;
	S::forEachMember([&](const ParamInfo& p, auto mp) {
		using T = std::decay_t<decltype(obj.*mp)>;
		if constexpr (std::is_same_v<T, bool>)
			if (std::string(p.name) == gate) on = obj.*mp, found = true;
	});
	if (!found) throw std::logic_error(std::string("parameter gate '") + gate + "' is not a bool parameter");
	return on;
}

template <class S>
void validateParamsOf(const S& obj)
{
	S::forEachMember([&](const ParamInfo& p, auto mp) {
		using T = std::decay_t<decltype(obj.*mp)>;
		if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
			if (paramGateOn(obj, p.gate)) p.check(Real(obj.*mp));
	});
}

} // namespace mpm
