//! Sweeps: a case key given an array of values stands for one case per value, named after the
//! case and the value (`incident_theta = [0, 45, 80]` in case `ggx` makes `ggx-theta0`,
//! `ggx-theta45` and `ggx-theta80`). Several swept keys make every combination. The swept keys
//! are `incident_theta` and `incident_phi` (lobe and user-sampler cases) and `params` (user
//! samplers: an array of lists, `params = [[0.3, 0.3], [0.1, 0.1]]`).

use super::Val;
use serde::Deserialize;
use std::ops::Range;
use toml::{Spanned, Value};

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
                super::spanned_items(seq).map(Values::Many)
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

/// One case of a sweep: the value of each key there (each as written where not swept), and the
/// suffix its name gets (empty where nothing is swept).
#[derive(Debug, Clone, Default)]
pub(super) struct Point {
    pub incident_theta: Option<Val>,
    pub incident_phi: Option<Val>,
    pub params: Option<Val>,
    pub suffix: String,
}

/// A value in a case name: numbers as written (45, 0.5, -30), lists joined by `_`.
fn label(v: &Value) -> String {
    match v {
        Value::Integer(i) => i.to_string(),
        Value::Float(f) => f.to_string(),
        Value::Array(items) => items.iter().map(label).collect::<Vec<_>>().join("_"),
        other => other.type_str().to_string(),
    }
}

/// Every combination of the swept keys' values, in the order theta, phi, params.
pub(super) fn points(theta: Option<&Sweep>, phi: Option<&Sweep>, params: Option<&Sweep>) -> Vec<Point> {
    type Set = fn(&mut Point, Val);
    type Split = fn(&Sweep) -> Option<Vec<Val>>;
    let keys: [(Option<&Sweep>, &str, Split, Set); 3] = [
        (theta, "theta", Sweep::scalars, |p, v| p.incident_theta = Some(v)),
        (phi, "phi", Sweep::scalars, |p, v| p.incident_phi = Some(v)),
        (params, "params", Sweep::lists, |p, v| p.params = Some(v)),
    ];
    let mut points = vec![Point::default()];
    for (sweep, short, values, set) in keys {
        let Some(sweep) = sweep else { continue };
        points = match values(sweep) {
            None => points.into_iter().map(|mut p| { set(&mut p, sweep.whole()); p }).collect(),
            Some(values) => points
                .into_iter()
                .flat_map(|p| {
                    values.iter().map(move |v| {
                        let mut q = p.clone();
                        q.suffix = format!("{}-{short}{}", q.suffix, label(v.get_ref()));
                        set(&mut q, v.clone());
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
    }

    /// (suffix, θ, φ, params) of each point.
    type Expanded = (String, Option<Value>, Option<Value>, Option<Value>);

    fn expand(toml_text: &str) -> Vec<Expanded> {
        let t: T = toml::from_str(toml_text).unwrap();
        points(t.theta.as_ref(), t.phi.as_ref(), t.params.as_ref())
            .into_iter()
            .map(|p| {
                let v = |x: Option<Val>| x.map(|x| x.into_inner());
                (p.suffix, v(p.incident_theta), v(p.incident_phi), v(p.params))
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
}
