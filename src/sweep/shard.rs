//! Shards: `--shard K/N` runs every N-th case starting at the K-th (1-based) of the sorted
//! case list; inside a Slurm job array K and N come from its variables.

use super::error::SweepError;

/// The K-th of N shards (1 ≤ K ≤ N).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { k: 1, n: 1 };

    pub fn new(k: usize, n: usize) -> Result<Shard, SweepError> {
        if n == 0 || k == 0 || k > n {
            return Err(SweepError::Shard(format!(
                "shard {k}/{n}: expected K/N with 1 <= K <= N"
            )));
        }
        Ok(Shard { k, n })
    }

    /// Reads `K/N`.
    pub fn parse(s: &str) -> Result<Shard, SweepError> {
        let bad = || SweepError::Shard(format!("--shard {s}: expected K/N, e.g. 2/8"));
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k = k.trim().parse().map_err(|_| bad())?;
        let n = n.trim().parse().map_err(|_| bad())?;
        Shard::new(k, n)
    }

    /// The shard of a Slurm job array task, read through `var` (`std::env::var` in the
    /// binary): none outside an array (no `SLURM_ARRAY_TASK_ID`). K is the task's position
    /// in the array, `(ID − MIN)/STEP + 1`, and N its size, `SLURM_ARRAY_TASK_COUNT` or
    /// `(MAX − MIN)/STEP + 1`; so `--array=1-16` and `--array=0-15` both give K = 1 … 16 of
    /// N = 16. Arrays with gaps (`--array=1,4,9`) are refused: use `--shard`.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>, SweepError> {
        let Some(id) = var("SLURM_ARRAY_TASK_ID") else {
            return Ok(None);
        };
        let num = |name: &str| -> Result<Option<usize>, SweepError> {
            match var(name) {
                None => Ok(None),
                Some(v) => v.trim().parse().map(Some).map_err(|_| {
                    SweepError::Shard(format!("{name} = {v:?}: expected a whole number"))
                }),
            }
        };
        let id = num("SLURM_ARRAY_TASK_ID")?.ok_or_else(|| {
            SweepError::Shard(format!(
                "SLURM_ARRAY_TASK_ID = {id:?}: expected a whole number"
            ))
        })?;
        let min = num("SLURM_ARRAY_TASK_MIN")?;
        let max = num("SLURM_ARRAY_TASK_MAX")?;
        let step = num("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
        let count = num("SLURM_ARRAY_TASK_COUNT")?;
        let min = min.unwrap_or(if id == 0 { 0 } else { 1 });
        if id < min || (id - min) % step != 0 {
            return Err(SweepError::Shard(format!(
                "SLURM_ARRAY_TASK_ID = {id} is not on the array {min}-{}:{step}; use --shard",
                max.map_or("?".into(), |m| m.to_string())
            )));
        }
        // the place of a task from `min` on, 1-based; none past the whole numbers
        let place = |task: usize, name: &str| {
            ((task - min) / step).checked_add(1).ok_or_else(|| {
                SweepError::Shard(format!(
                    "{name} = {task} with SLURM_ARRAY_TASK_MIN = {min}: an array of more tasks than can be counted ({} at most); use --shard",
                    usize::MAX
                ))
            })
        };
        let k = place(id, "SLURM_ARRAY_TASK_ID")?;
        let n =
            match (count, max) {
                (Some(c), _) => c,
                (None, Some(max)) if max >= min => place(max, "SLURM_ARRAY_TASK_MAX")?,
                _ => return Err(SweepError::Shard(
                    "a Slurm array task without SLURM_ARRAY_TASK_COUNT or SLURM_ARRAY_TASK_MAX: \
                     the array's size is unknown; use --shard"
                        .into(),
                )),
            };
        if let Some(max) = max {
            if max < min || place(max, "SLURM_ARRAY_TASK_MAX")? != n {
                return Err(SweepError::Shard(format!(
                    "the Slurm array {min}-{max}:{step} has gaps ({n} tasks); use --shard"
                )));
            }
        }
        Shard::new(k, n).map(Some).map_err(|_| {
            SweepError::Shard(format!(
                "SLURM_ARRAY_TASK_ID = {id} is task {k} of an array of {n} (SLURM_ARRAY_TASK_COUNT or SLURM_ARRAY_TASK_MAX); use --shard"
            ))
        })
    }

    /// Whether the case at 0-based `index` of the sorted list belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }

    /// `K/N`.
    pub fn label(&self) -> String {
        format!("{}/{}", self.k, self.n)
    }
}
