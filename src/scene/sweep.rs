//! Sweeps: a case key given an array of values stands for one case per value, named after the
//! case and the value (`incident_theta = [0, 45, 80]` in case `ggx` makes `ggx-theta0`,
//! `ggx-theta45` and `ggx-theta80`). Several swept keys make every combination (their product,
//! in the order of [`KEYS`]). Every key with one number or name sweeps: `method`, `alpha`,
//! `alpha_x`, `alpha_y`, `incident_theta`, `incident_phi`, `fresnel`, `f0`, `eta`, `k`, `masking`,
//! `samples` and `seed`; keys whose value is a list sweep over an array of lists: `params`
//! (user samplers, `params = [[0.3, 0.3], [0.1, 0.1]]`) and `bins` (`bins = [[32, 64], [64, 128]]`).

use serde::Deserialize;
use std::ops::Range;
use toml::{Spanned, Value};

/// A TOML value with its span in the file.
pub(super) type Val = Spanned<Value>;

/// The items of a TOML array, each with its span.
pub(super) fn spanned_items<'de, A: serde::de::SeqAccess<'de>>(mut seq: A) -> Result<Vec<Val>, A::Error> {
    let mut items = Vec::new();
    while let Some(item) = seq.next_element::<Val>()? {
        items.push(item);
    }
    Ok(items)
}

/// A key's value as written: one value, or an array of values each with its own span.
#[derive(Debug)]
pub(super) struct Sweep(Spanned<Values>);

#[derive(Debug)]
enum Values {
    One(Value),
    Many(Vec<Val>),
}

impl<'de> Deserialize<'de> for Sweep {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Spanned::<Values>::deserialize(d).map(Sweep)
    }
}

impl<'de> Deserialize<'de> for Values {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Values;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a value or an array of values (a sweep)")
            }
            fn visit_bool<E>(self, v: bool) -> Result<Values, E> {
                Ok(Values::One(Value::Boolean(v)))
            }
            fn visit_i64<E>(self, v: i64) -> Result<Values, E> {
                Ok(Values::One(Value::Integer(v)))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Values, E> {
                i64::try_from(v).map(|v| Values::One(Value::Integer(v))).map_err(|_| E::custom(format!("{v} is too large")))
            }
            fn visit_f64<E>(self, v: f64) -> Result<Values, E> {
                Ok(Values::One(Value::Float(v)))
            }
            fn visit_str<E>(self, v: &str) -> Result<Values, E> {
                Ok(Values::One(Value::String(v.into())))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Values, A::Error> {
                spanned_items(seq).map(Values::Many)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Values, A::Error> {
                Value::deserialize(serde::de::value::MapAccessDeserializer::new(map)).map(Values::One)
            }
        }
        d.deserialize_any(V)
    }
}

impl Sweep {
    pub fn span(&self) -> Range<usize> {
        self.0.span()
    }

    /// Whether it is an empty array (a sweep over no values).
    pub fn is_empty_sweep(&self) -> bool {
        matches!(self.0.get_ref(), Values::Many(items) if items.is_empty())
    }

    /// The whole value as written (an array as one value), for keys that do not sweep.
    pub fn whole(&self) -> Val {
        let value = match self.0.get_ref() {
            Values::One(v) => v.clone(),
            Values::Many(items) => Value::Array(items.iter().map(|i| i.get_ref().clone()).collect()),
        };
        Spanned::new(self.span(), value)
    }

    /// The values of a key whose single value is a number: an array is a sweep over its items.
    fn scalars(&self) -> Option<Vec<Val>> {
        match self.0.get_ref() {
            Values::Many(items) => Some(items.clone()),
            Values::One(_) => None,
        }
    }

    /// The values of a key whose single value is a list (`params`): an array whose items are
    /// all arrays is a sweep over them.
    fn lists(&self) -> Option<Vec<Val>> {
        match self.0.get_ref() {
            Values::Many(items) if !items.is_empty() && items.iter().all(|i| matches!(i.get_ref(), Value::Array(_))) => Some(items.clone()),
            _ => None,
        }
    }
}

/// A sweepable key: its name, the short label its values get in case names, and whether its
/// single value is a list (then an array of lists sweeps).
pub(super) struct Key {
    pub name: &'static str,
    label: &'static str,
    pub list: bool,
}

const fn key(name: &'static str, label: &'static str, list: bool) -> Key {
    Key { name, label, list }
}

/// Every sweepable key, in the order of the product (and of the name suffixes). The label of a
/// name key (method, fresnel, masking) is empty: the name alone is readable (`ggx-vndf`).
pub(super) const KEYS: [Key; 17] = [
    key("method", "", false),
    key("alpha", "alpha", false),
    key("alpha_x", "ax", false),
    key("alpha_y", "ay", false),
    key("alpha_angle", "turn", false),
    key("incident_theta", "theta", false),
    key("incident_phi", "phi", false),
    key("fresnel", "", false),
    key("f0", "f0_", false),
    key("eta", "eta", false),
    key("k", "k", false),
    key("masking", "", false),
    key("scatter", "", false),
    key("params", "params", true),
    key("bins", "bins", true),
    key("samples", "n", false),
    key("seed", "seed", false),
];

/// One case of a sweep: the value of each key of [`KEYS`] there (as written where not swept),
/// and the suffix its name gets (empty where nothing is swept).
#[derive(Debug, Clone, Default)]
pub(super) struct Point {
    values: [Option<Val>; KEYS.len()],
    pub suffix: String,
}

impl Point {
    /// The value of `key` (one of [`KEYS`]) at this point.
    pub fn get(&self, key: &str) -> Option<&Val> {
        let i = KEYS.iter().position(|k| k.name == key).unwrap_or_else(|| panic!("{key} is not a sweepable key"));
        self.values[i].as_ref()
    }
}

/// A value in a case name: numbers as written (45, 0.5, -30), names as they are, lists joined
/// by `_`.
fn label(v: &Value) -> String {
    match v {
        Value::Integer(i) => i.to_string(),
        Value::Float(f) => f.to_string(),
        Value::String(s) => s.clone(),
        Value::Array(items) => items.iter().map(label).collect::<Vec<_>>().join("_"),
        other => other.type_str().to_string(),
    }
}

/// The most cases a scene may make, its sweeps expanded (each case is listed, judged and written
/// to a folder of its own: 10⁵ cases are already hours of work and megabytes of names).
pub const MAX_CASES: u64 = 100_000;

/// The number of cases `sweeps` make, their product counted before anything is expanded, and
/// the swept keys that multiply with the number of values of each.
pub(super) fn count(sweeps: [Option<&Sweep>; KEYS.len()]) -> (u128, Vec<(&'static str, usize)>) {
    let factors: Vec<(&'static str, usize)> = KEYS
        .iter()
        .zip(sweeps)
        .filter_map(|(key, sweep)| {
            let values = sweep.and_then(|s| if key.list { s.lists() } else { s.scalars() })?;
            Some((key.name, values.len()))
        })
        .collect();
    // at most 17 factors, each under 2^32 (a TOML array's length): the product may pass u64
    let product = factors.iter().try_fold(1u128, |p, &(_, n)| p.checked_mul(n as u128)).unwrap_or(u128::MAX);
    (product, factors)
}

/// "alpha (100 values) × incident_theta (1000 values)", the factors of [`count`].
pub(super) fn describe(factors: &[(&str, usize)]) -> String {
    factors.iter().map(|(k, n)| format!("{k} ({n} values)")).collect::<Vec<_>>().join(" × ")
}

/// Every combination of the swept keys' values; `sweeps[i]` is the value of `KEYS[i]`.
pub(super) fn points(sweeps: [Option<&Sweep>; KEYS.len()]) -> Vec<Point> {
    let mut points = vec![Point::default()];
    for (i, (key, sweep)) in KEYS.iter().zip(sweeps).enumerate() {
        let Some(sweep) = sweep else { continue };
        let values = if key.list { sweep.lists() } else { sweep.scalars() };
        points = match values {
            None => points.into_iter().map(|mut p| { p.values[i] = Some(sweep.whole()); p }).collect(),
            Some(values) => points
                .into_iter()
                .flat_map(|p| {
                    values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.suffix = format!("{}-{}{}", q.suffix, key.label, label(v.get_ref()));
                        q.values[i] = Some(v.clone());
                        q
                    })
                })
                .collect(),
        };
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct T {
        theta: Option<Sweep>,
        phi: Option<Sweep>,
        params: Option<Sweep>,
        alpha: Option<Sweep>,
        method: Option<Sweep>,
    }

    /// (suffix, θ, φ, params) of each point.
    type Expanded = (String, Option<Value>, Option<Value>, Option<Value>);

    fn expand(toml_text: &str) -> Vec<Expanded> {
        let t: T = toml::from_str(toml_text).unwrap();
        let mut sweeps: [Option<&Sweep>; KEYS.len()] = Default::default();
        for (name, sweep) in [("incident_theta", &t.theta), ("incident_phi", &t.phi), ("params", &t.params), ("alpha", &t.alpha), ("method", &t.method)] {
            sweeps[KEYS.iter().position(|k| k.name == name).unwrap()] = sweep.as_ref();
        }
        points(sweeps)
            .into_iter()
            .map(|p| {
                let v = |key| p.get(key).map(|x| x.get_ref().clone());
                (p.suffix.clone(), v("incident_theta"), v("incident_phi"), v("params"))
            })
            .collect()
    }

    #[test]
    fn a_scalar_is_one_case_and_an_array_one_case_per_value() {
        let one = expand("theta = 30\nparams = [0.3, 0.4]");
        assert_eq!(one.len(), 1);
        assert_eq!(one[0].0, "");
        assert_eq!(one[0].1, Some(Value::Integer(30)));
        assert_eq!(one[0].3, Some(Value::Array(vec![Value::Float(0.3), Value::Float(0.4)])));

        let grid = expand("theta = [0, 45.5]\nphi = [-30, 90]\nparams = [[0.3, 0.3], [0.1, 0.2]]");
        let names: Vec<&str> = grid.iter().map(|g| g.0.as_str()).collect();
        assert_eq!(
            names,
            [
                "-theta0-phi-30-params0.3_0.3",
                "-theta0-phi-30-params0.1_0.2",
                "-theta0-phi90-params0.3_0.3",
                "-theta0-phi90-params0.1_0.2",
                "-theta45.5-phi-30-params0.3_0.3",
                "-theta45.5-phi-30-params0.1_0.2",
                "-theta45.5-phi90-params0.3_0.3",
                "-theta45.5-phi90-params0.1_0.2"
            ]
        );
        assert_eq!(grid[7].1, Some(Value::Float(45.5)));
        assert_eq!(grid[7].2, Some(Value::Integer(90)));
        assert_eq!(grid[7].3, Some(Value::Array(vec![Value::Float(0.1), Value::Float(0.2)])));
        assert!(expand("theta = []").is_empty());
    }

    /// The product is counted without expanding, also where it passes u64 (17 keys of 2^32).
    #[test]
    fn the_count_is_the_product_of_the_swept_keys() {
        let t: T = toml::from_str("theta = [0, 1, 2]\nphi = [1, 2]\nparams = [[0.1], [0.2], [0.3], [0.4]]\nalpha = 0.5").unwrap();
        let mut sweeps: [Option<&Sweep>; KEYS.len()] = Default::default();
        for (name, sweep) in [("incident_theta", &t.theta), ("incident_phi", &t.phi), ("params", &t.params), ("alpha", &t.alpha)] {
            sweeps[KEYS.iter().position(|k| k.name == name).unwrap()] = sweep.as_ref();
        }
        let (n, factors) = count(sweeps);
        assert_eq!(n, 24);
        assert_eq!(n as usize, points(sweeps).len());
        assert_eq!(describe(&factors), "incident_theta (3 values) × incident_phi (2 values) × params (4 values)");
    }

    #[test]
    fn names_and_numbers_sweep_in_the_order_of_the_keys() {
        let grid = expand("theta = [0, 60]\nalpha = [0.1, 0.3]\nmethod = [\"ndf\", \"vndf\"]");
        let names: Vec<&str> = grid.iter().map(|g| g.0.as_str()).collect();
        assert_eq!(names[..3], ["-ndf-alpha0.1-theta0", "-ndf-alpha0.1-theta60", "-ndf-alpha0.3-theta0"]);
        assert_eq!(names.len(), 8);
        assert_eq!(names[7], "-vndf-alpha0.3-theta60");
        assert_eq!(grid[7].1, Some(Value::Integer(60)));
    }
}
