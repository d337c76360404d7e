//! "Did you mean": the allowed word closest to a misspelt one, by Jaro–Winkler similarity
//! (`strsim`), as clap suggests subcommands.

/// Below this similarity nothing is suggested (clap's threshold for its suggestions is 0.7 of
/// plain Jaro; Jaro–Winkler weighs a shared prefix more).
const MIN_SIMILARITY: f64 = 0.8;

/// The candidate most like `word`, if any is like it at all.
///
/// ```
/// use lobes::suggest::closest;
/// assert_eq!(closest("alpah", ["alpha", "alpha_x", "lobe"]), Some("alpha"));
/// assert_eq!(closest("GGX", ["ward", "ggx"]), Some("ggx"));
/// assert_eq!(closest("phong", ["ward", "beckmann", "ggx"]), None);
/// ```
pub fn closest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let word = word.to_lowercase();
    candidates
        .into_iter()
        .map(|c| (strsim::jaro_winkler(&word, &c.to_lowercase()), c))
        .filter(|(s, _)| *s >= MIN_SIMILARITY)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c)
}

/// " (did you mean 'x'?)" for the candidate most like `word`, or "".
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    closest(word, candidates).map_or(String::new(), |c| format!(" (did you mean '{c}'?)"))
}

/// A serde "unknown field `x`, expected one of `a`, `b`" message with the closest of the
/// expected fields suggested.
pub fn unknown_field(message: &str) -> String {
    let quoted = |s: &str| s.split('`').skip(1).step_by(2).map(str::to_string).collect::<Vec<_>>();
    let Some(rest) = message.strip_prefix("unknown field `") else { return message.to_string() };
    let Some((field, expected)) = rest.split_once('`') else { return message.to_string() };
    let expected = quoted(expected);
    format!("{message}{}", did_you_mean(field, expected.iter().map(String::as_str)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_fields_get_the_closest_expected_one() {
        assert_eq!(
            unknown_field("unknown field `incident_tehta`, expected one of `name`, `incident_theta`, `incident_phi`"),
            "unknown field `incident_tehta`, expected one of `name`, `incident_theta`, `incident_phi` (did you mean 'incident_theta'?)"
        );
        assert_eq!(unknown_field("unknown field `zzz`, expected `name`"), "unknown field `zzz`, expected `name`");
        assert_eq!(unknown_field("invalid type"), "invalid type");
        assert_eq!(did_you_mean("vndff", ["ndf", "vndf", "bounded"]), " (did you mean 'vndf'?)");
        assert_eq!(did_you_mean("", ["ndf"]), "");
    }
}
