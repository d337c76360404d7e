//! `lobes run --case PATTERN`: the cases of a scene whose names match shell-style patterns
//! (`ggx-*`, `*-theta4?`, `[gw]*`; `glob`'s syntax, ignoring case as case names do).

use super::suggest::did_you_mean;
use super::{Scene, Slot};
use glob::{MatchOptions, Pattern};

const OPTIONS: MatchOptions = MatchOptions { case_sensitive: false, require_literal_separator: false, require_literal_leading_dot: false };

impl Scene {
    /// The scene with only the cases that match one of `patterns` (all of them if there are
    /// none), in the scene's order. A pattern that is not valid, or that matches no case, is an
    /// error that names the closest case name and the cases there are.
    ///
    /// ```
    /// let text = "[[case]]\nname = \"g\"\nlobe = \"ggx\"\nalpha = [0.1, 0.3]\n\n[[case]]\nname = \"w\"\nlobe = \"ward\"\nalpha = 0.2\n";
    /// let scene = lobes::scene::Scene::parse("s.toml", text).unwrap();
    /// let picked = scene.select(&["g-*".to_string()]).unwrap();
    /// assert_eq!(picked.entries().map(|(e, _)| e.name().to_string()).collect::<Vec<_>>(), ["g-alpha0.1", "g-alpha0.3"]);
    /// assert!(scene.select(&["x".to_string()]).unwrap_err().contains("matches no case"));
    /// ```
    pub fn select(&self, patterns: &[String]) -> Result<Scene, String> {
        if patterns.is_empty() {
            return Ok(self.clone());
        }
        let names: Vec<&str> = self.entries().map(|(e, _)| e.name()).collect();
        let mut compiled = Vec::new();
        for p in patterns {
            let pattern = Pattern::new(p).map_err(|e| format!("{p:?} is not a valid pattern: {e}"))?;
            if !names.iter().any(|n| pattern.matches_with(n, OPTIONS)) {
                let hint = did_you_mean(p, names.iter().copied());
                return Err(format!("{p:?} matches no case of {}{hint}; its cases: {}", self.file, names.join(", ")));
            }
            compiled.push(pattern);
        }
        let mut picked = Scene { cases: Vec::new(), user_cases: Vec::new(), file: self.file.clone(), order: Vec::new() };
        for (&(slot, at), name) in self.order.iter().zip(&names) {
            if !compiled.iter().any(|p| p.matches_with(name, OPTIONS)) {
                continue;
            }
            let slot = match slot {
                Slot::Lobe(i) => {
                    picked.cases.push(self.cases[i].clone());
                    Slot::Lobe(picked.cases.len() - 1)
                }
                Slot::User(i) => {
                    picked.user_cases.push(self.user_cases[i].clone());
                    Slot::User(picked.user_cases.len() - 1)
                }
            };
            picked.order.push((slot, at));
        }
        Ok(picked)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[[case]]\nname = \"ggx\"\nlobe = \"ggx\"\nalpha = 0.3\nincident_theta = [0, 45]\n\n\
                        [[case]]\nname = \"Ward\"\nlobe = \"ward\"\nalpha = 0.2\n\n\
                        [[case]]\nname = \"disc\"\nlobe = \"discrete\"\nweights = [1, 2]\n";

    fn names(s: &Scene) -> Vec<String> {
        s.entries().map(|(e, _)| e.name().to_string()).collect()
    }

    #[test]
    fn patterns_pick_cases_in_the_scenes_order_and_keep_their_locations() {
        let scene = Scene::parse("s.toml", TEXT).unwrap();
        let picked = scene.select(&["disc".into(), "ggx-*45".into(), "ward".into()]).unwrap();
        assert_eq!(names(&picked), ["ggx-theta45", "Ward", "disc"]);
        assert_eq!(picked.cases.len(), 3);
        assert_eq!(picked.case_location(2), "s.toml:12:1");
        assert_eq!(names(&scene.select(&[]).unwrap()).len(), 4);
        let err = scene.select(&["ggx-theta4".into()]).unwrap_err();
        assert!(err.contains("matches no case of s.toml (did you mean 'ggx-theta45'?); its cases: ggx-theta0, ggx-theta45, Ward, disc"), "{err}");
        assert!(scene.select(&["[".into()]).unwrap_err().contains("not a valid pattern"));
    }
}
