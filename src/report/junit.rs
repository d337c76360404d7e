//! `OUT/junit.xml`: a run's summary ([`RunSummary`]) in the JUnit XML that CI systems read.
//! One `<testcase>` per case of the scene: a pass, a `<failure>` with the reason the case failed
//! (χ², albedo, a user's checks), an `<error>` where the tool could not run it, or `<skipped>`
//! where an interrupted run never started it. Written by `quick-junit`, which escapes the XML.

use super::output::RunSummary;
use quick_junit::{NonSuccessKind, Property, Report, TestCase, TestCaseStatus, TestSuite};
use std::time::Duration;

/// The suite's name and every test case's class name.
pub const SUITE: &str = "lobes";

/// The JUnit XML of a run.
pub fn to_xml(summary: &RunSummary) -> anyhow::Result<String> {
    let mut suite = TestSuite::new(SUITE);
    suite.add_properties([
        Property::new("lobes_version", summary.lobes_version.as_str()),
        Property::new("adapter", summary.adapter.as_str()),
        Property::new("backend", summary.backend.as_str()),
        Property::new("status", summary.status.name()),
        Property::new("significance", summary.significance.to_string()),
        Property::new("per_case_significance", summary.per_case_significance.to_string()),
    ]);
    for case in &summary.cases {
        let status = match (&case.error, case.passed) {
            (Some(error), _) => non_success(NonSuccessKind::Error, error),
            (None, true) => TestCaseStatus::success(),
            (None, false) => non_success(NonSuccessKind::Failure, case.failure.as_deref().unwrap_or("failed its checks")),
        };
        let mut test = TestCase::new(case.case.as_str(), status);
        test.set_classname(SUITE);
        if let Some(m) = &case.measured {
            test.set_time(Duration::from_secs_f64(m.gpu_seconds.unwrap_or(m.wall_seconds).max(0.0)));
            test.add_properties([
                Property::new("chi2", m.chi2.to_string()),
                Property::new("dof", m.dof.to_string()),
                Property::new("p_value", m.p_value.to_string()),
            ]);
            // the family's p-value, and each test's (the fine grid, aggregations, marginals)
            if let Some(p) = m.family_p_value {
                test.add_property(Property::new("family_p_value", p.to_string()));
            }
            test.add_properties(m.family.iter().map(|t| Property::new(format!("p_value {}", t.test), t.p_value.to_string())));
        }
        suite.add_test_case(test);
    }
    for name in &summary.not_run {
        let mut status = TestCaseStatus::skipped();
        status.set_message("not run: the run was interrupted before this case");
        let mut test = TestCase::new(name.as_str(), status);
        test.set_classname(SUITE);
        suite.add_test_case(test);
    }
    if let Some(error) = &summary.error {
        // a run that ran nothing is one test that could not run, not an empty (passing) suite
        let mut test = TestCase::new(SUITE, non_success(NonSuccessKind::Error, error));
        test.set_classname(SUITE);
        suite.add_test_case(test);
    }
    let mut report = Report::new(SUITE);
    report.add_test_suite(suite);
    Ok(report.to_string()?)
}

fn non_success(kind: NonSuccessKind, message: &str) -> TestCaseStatus {
    let mut status = TestCaseStatus::non_success(kind);
    status.set_message(message);
    status
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::output::{CaseMeasured, CaseSummary, RunStatus};

    fn case(name: &str, passed: bool, failure: Option<&str>, error: Option<&str>) -> CaseSummary {
        CaseSummary {
            case: name.into(),
            samples: 100,
            shards: None,
            backend: None,
            passed,
            failed_checks: None,
            failure: failure.map(String::from),
            measured: error.is_none().then_some(CaseMeasured {
                gpu_seconds: None,
                wall_seconds: 1.5,
                chi2: 3.0,
                dof: 2,
                p_value: 0.2,
                family_p_value: Some(0.4),
                family: vec![crate::stats::chi2::FamilyTest { test: "2 × 4".into(), rows: 2, cols: 4, statistic: 3.0, dof: 2, p_value: 0.2, holm_p_value: 0.4, rejected: false }],
                albedo: None,
                max_angle_rad: None,
            }),
            error: error.map(String::from),
            output: None,
        }
    }

    #[test]
    fn every_case_is_a_testcase_with_its_verdict_and_reasons_are_escaped() {
        let mut s = RunSummary::new("lavapipe <x> & \"y\"".into(), "gpu".into(), 0.01, 0.005);
        s.push(case("ok", true, None, None));
        s.push(case("bad", false, Some("χ² = 90.0 with 2 dof, p < 1e-9 & <worse>"), None));
        s.push(case("broken", false, None, Some("cannot write out/broken/residual.png")));
        s.status = RunStatus::Interrupted;
        s.not_run = vec!["later".into()];
        assert_eq!((s.failed, s.errors), (1, 1));
        let xml = to_xml(&s).unwrap();
        let back = Report::deserialize_from_str(&xml).unwrap_or_else(|e| panic!("{e}\n{xml}"));
        let suite = &back.test_suites[0];
        assert_eq!((suite.tests, suite.failures, suite.errors), (4, 1, 1), "{xml}");
        assert!(xml.contains(r#"skipped="1""#), "{xml}");
        let by_name = |n: &str| suite.test_cases.iter().find(|c| c.name.as_str() == n).unwrap();
        assert!(matches!(by_name("ok").status, TestCaseStatus::Success { .. }));
        match &by_name("bad").status {
            TestCaseStatus::NonSuccess { kind: NonSuccessKind::Failure, message, .. } => {
                assert_eq!(message.as_ref().unwrap().as_str(), "χ² = 90.0 with 2 dof, p < 1e-9 & <worse>")
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(by_name("broken").status, TestCaseStatus::NonSuccess { kind: NonSuccessKind::Error, .. }));
        assert!(matches!(by_name("later").status, TestCaseStatus::Skipped { .. }));
        assert_eq!(by_name("ok").time, Some(Duration::from_secs_f64(1.5)));
        let adapter = suite.properties.iter().find(|p| p.name.as_str() == "adapter").unwrap();
        assert_eq!(adapter.value.as_str(), "lavapipe <x> & \"y\"");
        // every test of the family's p-value
        let property = |n: &str| by_name("ok").properties.iter().find(|p| p.name.as_str() == n).map(|p| p.value.to_string());
        assert_eq!((property("family_p_value"), property("p_value 2 × 4")), (Some("0.4".into()), Some("0.2".into())));
        assert!(xml.contains("&lt;worse&gt;") && xml.contains("&amp;"), "{xml}");
    }
}
