//! JSON Schemas (draft 2020-12) of every JSON file lobes writes, generated from the serde
//! structs that write and read them. `docs/schema/` holds them; `tests/schema.rs` checks that
//! they are up to date and that the files of a run, a shard run, a merge and a check validate.

use super::output::{HistogramFile, RunSummary, ShardSummary, TimingFile};
use crate::check::Report as CheckReport;
use crate::check::power::PowerSweep;
use crate::run::shard::ShardFile;
use schemars::{JsonSchema, schema_for};

/// Each output's schema and its file name in `docs/schema/`.
pub fn schemas() -> Vec<(&'static str, serde_json::Value)> {
    fn one<T: JsonSchema>(name: &'static str) -> (&'static str, serde_json::Value) {
        (name, schema_for!(T).to_value())
    }
    vec![
        // DIR/<case>/histogram.json of `lobes run` and `lobes merge`
        one::<HistogramFile>("histogram.schema.json"),
        // DIR/<case>/timing.json of `lobes run` and `lobes merge`
        one::<TimingFile>("timing.schema.json"),
        // DIR/<case>/shard-I-of-N.json of `lobes run --shard I/N`
        one::<ShardFile>("shard.schema.json"),
        // stdout of `lobes run --json` and `lobes merge --json`
        one::<RunSummary>("run-summary.schema.json"),
        // stdout of `lobes run --shard I/N --json`
        one::<ShardSummary>("shard-summary.schema.json"),
        // stdout of `lobes check --json`, and DIR/report.json of `lobes check --out DIR`
        one::<CheckReport>("check-report.schema.json"),
        // stdout of `lobes check --power --json`, and DIR/power.json with --out DIR
        one::<PowerSweep>("check-power.schema.json"),
    ]
}

/// A schema as stored in `docs/schema/`: pretty-printed, with a final newline.
pub fn to_text(schema: &serde_json::Value) -> String {
    serde_json::to_string_pretty(schema).expect("a schema serialises") + "\n"
}
