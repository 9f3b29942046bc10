//! `englobe farm slurm`: one image rendered as tiles by a Slurm job array, then assembled.
//!
//! The tiles folder (on a file system every node sees) is the whole state of a run: the tiles
//! already there and valid for this scene and these options are kept, the ids of jobs submitted
//! earlier are in its `jobs` file, and the command always (re)submits only the tiles still
//! missing, after waiting for any earlier job still queued. So a run stopped anywhere (the command
//! killed, a task cancelled or failed, a node lost) is completed by running the same command
//! again, and a finished run just assembles again.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use englobe_render::tile::assemble::{Tile, assemble};
use englobe_render::tile::file::{VERSION, read_tile};
use englobe_render::{TileSpec, write_image_with};

use crate::image_options::{Balance, ImageOptions, render_digest};
use crate::render_cmd::read_scene;
use crate::slurm::{self, Submission, shell_quote};

#[derive(Args)]
pub struct FarmArgs {
    #[command(subcommand)]
    scheduler: Scheduler,
}

#[derive(Subcommand)]
enum Scheduler {
    /// Render through a Slurm job array: one task per tile, then assemble; run the same command
    /// again to complete a run that was interrupted or lost tiles.
    Slurm(SlurmArgs),
}

#[derive(Args)]
struct SlurmArgs {
    /// Scene file (TOML); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// The image to write (.png or .exr).
    #[arg(short, long)]
    output: PathBuf,
    /// Number of tiles (horizontal strips), one array task each.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    tiles: u32,
    /// Folder for the tiles, the batch script and the logs, on a file system that every node
    /// sees (default: the output's name with `.tiles`).
    #[arg(long, value_name = "DIR")]
    tiles_dir: Option<PathBuf>,
    /// Slurm partition to submit to (default: the cluster's default partition).
    #[arg(long)]
    partition: Option<String>,
    /// Time limit of each task, in Slurm's format (`10:00`, `1-00:00:00`).
    #[arg(long)]
    time: Option<String>,
    /// Cores per task; each task renders on that many threads.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=4096))]
    cpus_per_task: u32,
    /// Further argument for sbatch (repeatable), such as `--sbatch-arg=--account=proj`.
    #[arg(long, value_name = "ARG", allow_hyphen_values = true)]
    sbatch_arg: Vec<String>,
    /// Continue an earlier run in the tiles folder: render only its missing tiles. The same
    /// command without --resume does that too; with it, a folder that holds no earlier run is an
    /// error rather than the start of a new one.
    #[arg(long)]
    resume: bool,
    /// How the image is cut: strips of equal height (area) or of equal predicted cost (cost: every
    /// task first makes a quick pass of the cost AOV, so that the slowest task is not much slower
    /// than the mean).
    #[arg(long, value_enum, default_value_t = Balance::Area)]
    balance: Balance,
    /// Seconds between two looks at the queue.
    #[arg(long, default_value_t = 2.0, value_name = "SECONDS")]
    poll: f64,
    #[command(flatten)]
    image: ImageOptions,
    /// Print only errors.
    #[arg(short, long)]
    quiet: bool,
}

pub fn run(args: FarmArgs) -> anyhow::Result<ExitCode> {
    match args.scheduler {
        Scheduler::Slurm(a) => run_slurm(a),
    }
}

/// What the run must produce, and where its tiles go.
struct Plan {
    dir: PathBuf,
    digest: String,
    width: u32,
    height: u32,
    count: u32,
}

impl Plan {
    fn tile_path(&self, index: u32) -> PathBuf {
        let digits = (self.count - 1).to_string().len().max(4);
        self.dir.join(format!("tile-{index:0digits$}.exr"))
    }

    fn jobs_file(&self) -> PathBuf {
        self.dir.join("jobs")
    }

    /// The tiles already rendered for this plan, and the indices still missing. A tile of
    /// another render in the folder is an error: it would mean two runs share the folder.
    fn survey(&self) -> anyhow::Result<(Vec<Tile>, Vec<u32>)> {
        let (mut done, mut missing) = (Vec::new(), Vec::new());
        for spec in TileSpec::all(self.count) {
            let path = self.tile_path(spec.index);
            if !path.exists() {
                missing.push(spec.index);
                continue;
            }
            match read_tile(&path) {
                Ok((header, film)) => {
                    let ours = header.scene_digest == self.digest
                        && header.version == VERSION
                        && (header.full_width, header.full_height) == (self.width, self.height)
                        && header.tile == Some(spec);
                    if !ours {
                        bail!(
                            "{}: a tile of another render (another scene, options, version or cut); \
                             remove {} or choose another --tiles-dir",
                            path.display(),
                            self.dir.display()
                        );
                    }
                    done.push(Tile { path, header, film });
                }
                // A broken tile (a task killed while writing cannot leave one: tiles are written
                // atomically) is rendered again.
                Err(e) => {
                    eprintln!("warning: {e}; rendering it again");
                    missing.push(spec.index);
                }
            }
        }
        Ok((done, missing))
    }

    /// Ids of the jobs submitted for this folder so far.
    fn jobs(&self) -> anyhow::Result<Vec<String>> {
        match std::fs::read_to_string(self.jobs_file()) {
            Ok(text) => Ok(text.lines().map(str::trim).filter(|l| !l.is_empty()).map(str::to_owned).collect()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
            Err(e) => Err(e).with_context(|| format!("{}: cannot read", self.jobs_file().display())),
        }
    }

    fn record_job(&self, id: &str) -> anyhow::Result<()> {
        let path = self.jobs_file();
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
        writeln!(f, "{id}").with_context(|| format!("{}: cannot write", path.display()))
    }
}

fn run_slurm(args: SlurmArgs) -> anyhow::Result<ExitCode> {
    let say = |text: String| {
        if !args.quiet {
            println!("{text}");
        }
    };
    englobe_render::OutputFormat::from_path(&args.output)?;
    if args.scene.as_ref().is_some_and(|p| p.as_os_str() == "-") {
        bail!("the farm's tasks read the scene from a file: give its path, not `-`");
    }
    let (mut scene, _) = read_scene(args.scene.as_ref(), &args.image.overrides(), false)?;
    args.image.apply(&mut scene)?;
    let (width, height) = (scene.image.width, scene.image.height);
    TileSpec { index: 0, count: args.tiles }.window(width, height).map_err(anyhow::Error::msg)?;
    let dir = args.tiles_dir.clone().unwrap_or_else(|| {
        let mut name = args.output.clone().into_os_string();
        name.push(".tiles");
        PathBuf::from(name)
    });
    let plan =
        Plan { dir, digest: render_digest(&scene, args.image.accel, args.balance), width, height, count: args.tiles };
    // A look at the names only: the tiles themselves are read once the queue is clear.
    let earlier_run = plan.jobs_file().exists() || (0..plan.count).any(|k| plan.tile_path(k).exists());
    if args.resume && !earlier_run {
        bail!("{}: no earlier run to resume (no tiles, no jobs file)", plan.dir.display());
    }
    std::fs::create_dir_all(plan.dir.join("logs"))
        .with_context(|| format!("{}: cannot create the tiles folder", plan.dir.display()))?;
    let dir = std::path::absolute(&plan.dir).with_context(|| format!("{}: no absolute path", plan.dir.display()))?;

    // Jobs of an earlier run that are still queued or running finish first, so that no tile is
    // rendered twice at once.
    let earlier = plan.jobs()?;
    if slurm::active_tasks(&earlier)? > 0 {
        say(format!("waiting for the tasks still queued from job {}", earlier.join(", ")));
        wait_for(&earlier, &plan, args.poll, args.quiet)?;
    }

    let (_, missing) = plan.survey()?;
    let mut submitted = Vec::new();
    if !missing.is_empty() {
        let script = dir.join("job.sbatch");
        write_script(&script, &args, &plan, &dir)?;
        let how = Submission {
            job_name: format!("englobe-{}", stem(args.scene.as_deref())),
            log_pattern: dir.join("logs").join("%A_%a.out"),
            cpus_per_task: args.cpus_per_task,
            partition: args.partition.clone(),
            time: args.time.clone(),
            extra: args.sbatch_arg.clone(),
        };
        let id = slurm::submit(&script, &missing, &how)?;
        plan.record_job(&id)?;
        say(format!(
            "submitted job {id}: {} of {} tiles ({}), logs in {}",
            missing.len(),
            plan.count,
            slurm::array_list(&missing),
            dir.join("logs").display()
        ));
        submitted.push(id);
        wait_for(&submitted, &plan, args.poll, args.quiet)?;
    }

    let (done, missing) = plan.survey()?;
    if !missing.is_empty() {
        let jobs = plan.jobs()?;
        let mut message = format!("{} of {} tiles missing after the job ended:", missing.len(), plan.count);
        for &k in missing.iter().take(8) {
            message.push_str(&format!("\n  tile {k}/{}{}", plan.count, last_log_line(&dir, &jobs, k)));
        }
        message.push_str("\nrun the same command again (or with --resume) to render only the missing tiles");
        bail!(message);
    }
    let film = assemble(&done)?;
    write_image_with(&film, &args.output, &scene.image.output)?;
    say(format!("wrote {} ({width}x{height} from {} tiles in {})", args.output.display(), plan.count, dir.display()));
    Ok(ExitCode::SUCCESS)
}

/// Waits until the jobs have no task pending or running, showing how many tiles exist.
fn wait_for(jobs: &[String], plan: &Plan, poll: f64, quiet: bool) -> anyhow::Result<()> {
    let bar = crate::progress::tile_bar(plan.count as usize, quiet);
    let poll = Duration::from_secs_f64(poll.clamp(0.05, 3600.0));
    let start = Instant::now();
    let mut failures = 0;
    loop {
        bar.set_position((0..plan.count).filter(|&k| plan.tile_path(k).exists()).count() as u64);
        match slurm::active_tasks(jobs) {
            Ok(0) => break,
            Ok(_) => failures = 0,
            // The controller may be restarting: a few failed looks in a row are tolerated.
            Err(e) if failures < 10 => {
                failures += 1;
                eprintln!("warning: {e:#}; trying again");
            }
            Err(e) => return Err(e),
        }
        std::thread::sleep(poll);
    }
    bar.finish_and_clear();
    if !quiet {
        println!("job {} done after {:.1} s", jobs.join(", "), start.elapsed().as_secs_f64());
    }
    Ok(())
}

/// The batch script every task runs: `englobe render` of its tile, with the run's options.
fn write_script(path: &Path, args: &SlurmArgs, plan: &Plan, dir: &Path) -> anyhow::Result<()> {
    let exe = std::env::current_exe().context("cannot find the englobe binary to run in the tasks")?;
    let mut render = vec![shell_quote(&exe.to_string_lossy()), "render".to_owned()];
    if let Some(scene) = &args.scene {
        let scene = std::path::absolute(scene).with_context(|| format!("{}: no absolute path", scene.display()))?;
        render.push(shell_quote(&scene.to_string_lossy()));
    }
    let digits = (plan.count - 1).to_string().len().max(4);
    render.push(format!("--tile \"$k/{}\"", plan.count));
    render.push(format!("-o {}/tile-$(printf %0{digits}d \"$k\").exr", shell_quote(&dir.to_string_lossy())));
    render.push("--threads \"${SLURM_CPUS_PER_TASK:-1}\"".to_owned());
    render.extend(args.image.to_args().iter().map(|a| shell_quote(a)));
    if args.balance == Balance::Cost {
        render.push("--balance cost".to_owned());
    }
    let text = format!(
        "#!/bin/bash\n\
         # Written by `englobe farm slurm`: array task K renders tile K of {count}; submitted by\n\
         # englobe with sbatch --array=... (the tiles still missing), --requeue and --output={logs}.\n\
         set -euo pipefail\n\
         k=\"$SLURM_ARRAY_TASK_ID\"\n\
         exec {render}\n",
        count = plan.count,
        logs = dir.join("logs").join("%A_%a.out").display(),
        render = render.join(" "),
    );
    englobe_render::output::write_atomically(path, |w| {
        w.write_all(text.as_bytes()).map_err(|error| englobe_render::OutputError::Io { path: path.to_owned(), error })
    })?;
    Ok(())
}

/// The scene's file name without extension, for the job name.
fn stem(scene: Option<&Path>) -> String {
    scene.and_then(|p| p.file_stem()).map_or("default".into(), |s| s.to_string_lossy().into_owned())
}

/// `: <last line of the task's log>` from the newest job that has a log for tile `k`.
fn last_log_line(dir: &Path, jobs: &[String], k: u32) -> String {
    for job in jobs.iter().rev() {
        let log = dir.join("logs").join(format!("{job}_{k}.out"));
        if let Ok(text) = std::fs::read_to_string(&log) {
            let last = text.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("(empty log)");
            return format!(": {} says `{}`", log.display(), last.trim());
        }
    }
    String::new()
}
