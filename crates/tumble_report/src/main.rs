//! `tumble-report`: runs the work–precision study and the stability matrix, writes
//! `report.md`, `results.json` and SVG plots (the same as `tumble report`).

tumble_scene::tool_main!(
    /// tumble's accuracy report: error against run time, and the stability matrix.
    tumble_report::run::ReportOptions,
    tumble_report::run::run_report
);
