//! The little of Slurm that `englobe farm slurm` uses, through its own commands: `sbatch` submits
//! one job array (one task per tile), `squeue` says which tasks are still pending or running.
//! Nothing here schedules: Slurm does, with its job arrays, `--requeue` for tasks whose node
//! fails, and its own logs.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

/// How to submit the tasks.
#[derive(Clone, Debug, Default)]
pub struct Submission {
    /// Name of the job in `squeue`.
    pub job_name: String,
    /// Slurm's `--output` pattern for the tasks' logs.
    pub log_pattern: PathBuf,
    /// Cores per task (`--cpus-per-task`); the task renders on that many threads.
    pub cpus_per_task: u32,
    /// `--partition`, if given.
    pub partition: Option<String>,
    /// `--time` (the task's time limit), if given.
    pub time: Option<String>,
    /// Further `sbatch` arguments, passed as they are.
    pub extra: Vec<String>,
}

/// The array indices as Slurm's `--array` list: runs of consecutive indices as ranges (`0-3,6`).
pub fn array_list(indices: &[u32]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let start = indices[i];
        while i + 1 < indices.len() && indices[i + 1] == indices[i] + 1 {
            i += 1;
        }
        parts.push(if indices[i] == start { start.to_string() } else { format!("{start}-{}", indices[i]) });
        i += 1;
    }
    parts.join(",")
}

/// Submits `script` as a job array over `indices` and returns the job's id.
pub fn submit(script: &Path, indices: &[u32], how: &Submission) -> anyhow::Result<String> {
    let mut cmd = Command::new("sbatch");
    cmd.arg("--parsable")
        .arg(format!("--array={}", array_list(indices)))
        .arg(format!("--job-name={}", how.job_name))
        .arg(format!("--output={}", how.log_pattern.display()))
        .arg("--requeue")
        .arg(format!("--cpus-per-task={}", how.cpus_per_task));
    if let Some(p) = &how.partition {
        cmd.arg(format!("--partition={p}"));
    }
    if let Some(t) = &how.time {
        cmd.arg(format!("--time={t}"));
    }
    cmd.args(&how.extra).arg(script);
    let out = cmd.output().context("cannot run `sbatch` (is Slurm installed and on the PATH?)")?;
    if !out.status.success() {
        bail!("sbatch refused the job ({}): {}", out.status, String::from_utf8_lossy(&out.stderr).trim());
    }
    // `--parsable` prints `id` or `id;cluster`.
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or_default().to_owned();
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!("sbatch answered `{}`; expected a job id", text.trim());
    }
    Ok(id)
}

/// How many of the jobs' tasks are still pending or running (a pending range counts as its
/// size). A job Slurm no longer knows has none.
pub fn active_tasks(jobs: &[String]) -> anyhow::Result<usize> {
    if jobs.is_empty() {
        return Ok(0);
    }
    let out = Command::new("squeue")
        .args(["--noheader", "--array", "--format=%i %T", "--jobs"])
        .arg(jobs.join(","))
        .output()
        .context("cannot run `squeue` (is Slurm installed and on the PATH?)")?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        // Once a job has left the controller's memory, squeue calls its id invalid.
        if stderr.contains("Invalid job id") {
            return Ok(0);
        }
        bail!("squeue failed ({}): {}", out.status, stderr.trim());
    }
    let text = String::from_utf8_lossy(&out.stdout);
    Ok(text
        .lines()
        .filter(|l| {
            let state = l.split_whitespace().nth(1).unwrap_or("");
            !matches!(state, "COMPLETED" | "FAILED" | "CANCELLED" | "TIMEOUT" | "OUT_OF_MEMORY" | "NODE_FAIL" | "")
        })
        .count())
}

/// Quotes `s` for a POSIX shell: single quotes, with each `'` written as `'\''`.
pub fn shell_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_lists_are_compressed_into_ranges() {
        assert_eq!(array_list(&[0, 1, 2, 3]), "0-3");
        assert_eq!(array_list(&[3]), "3");
        assert_eq!(array_list(&[0, 2, 3, 4, 7, 9, 10]), "0,2-4,7,9-10");
        assert_eq!(array_list(&[]), "");
    }

    #[test]
    fn shell_quoting_survives_quotes_and_spaces() {
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
    }
}
