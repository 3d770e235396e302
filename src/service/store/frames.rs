//! The frames of a job's time series (`output.frames`): each stored under the claim's lease as
//! the run reaches it (a run that starts over writes them again), in parts of at most
//! [`PART_PARTICLES`] particles so that a reader holds one part of the stored form at a time,
//! and gone with the job or when its run fails or is cancelled.

use super::database::{Result, Store};
use super::lease::holds;
use crate::export::series::{FrameTime, FRAME_BYTES_PER_PARTICLE};
use sqlx::Row;
use uuid::Uuid;

/// Particles in one stored part of a frame (3.5 MB).
pub const PART_PARTICLES: usize = 65_536;

/// One frame as the worker stores it.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredFrame {
    pub at: FrameTime,
    pub particles: usize,
    /// The stored form (`export::series::encode`).
    pub data: Vec<u8>,
}

impl Store {
    /// Stores `frame` as job `id`'s (replacing one of the same index) while `lease` holds the
    /// job; false when the lease was lost: nothing is written.
    pub async fn save_frame(&self, id: Uuid, lease: Uuid, frame: &StoredFrame) -> Result<bool> {
        let mut tx = self.write().await?;
        if holds(&self.backend, &mut tx, id, lease).await?.is_none() {
            return Ok(false);
        }
        let (job, k) = (id.to_string(), frame.at.index as i64);
        sqlx::query("DELETE FROM frames WHERE job_id = $1 AND k = $2")
            .bind(&job)
            .bind(k)
            .execute(&mut *tx)
            .await?;
        let part_bytes = PART_PARTICLES * FRAME_BYTES_PER_PARTICLE;
        for (part, data) in frame.data.chunks(part_bytes).enumerate() {
            sqlx::query(
                "INSERT INTO frames (job_id, k, part, travel_mm, time_ms, particles, data) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7)",
            )
            .bind(&job)
            .bind(k)
            .bind(part as i64)
            .bind(frame.at.travel_mm)
            .bind(frame.at.time_ms)
            .bind(frame.particles as i64)
            .bind(data)
            .execute(&mut *tx)
            .await?;
        }
        tx.commit().await?;
        Ok(true)
    }

    /// Where each of job `id`'s stored frames stands, in order (none: an empty list).
    pub async fn frame_times(&self, id: Uuid) -> Result<Vec<FrameTime>> {
        let rows: Vec<(i64, f64, f64)> = sqlx::query_as(
            "SELECT k, travel_mm, time_ms FROM frames WHERE job_id = $1 AND part = 0 ORDER BY k",
        )
        .bind(id.to_string())
        .fetch_all(&self.pool)
        .await?;
        Ok(rows
            .into_iter()
            .map(|(k, travel_mm, time_ms)| FrameTime {
                index: k.clamp(0, u32::MAX as i64) as u32,
                travel_mm,
                time_ms,
            })
            .collect())
    }

    /// Frame `k` of job `id`, if stored: where it stands and its particle count, after handing
    /// `part` each stored part in order, read in place from its row (one part at a time).
    pub async fn frame(
        &self,
        id: Uuid,
        k: u32,
        mut part: impl FnMut(usize, &[u8]),
    ) -> Result<Option<(FrameTime, usize)>> {
        let mut found = None;
        for index in 0i64.. {
            let row = sqlx::query(
                "SELECT travel_mm, time_ms, particles, data FROM frames \
                 WHERE job_id = $1 AND k = $2 AND part = $3",
            )
            .bind(id.to_string())
            .bind(k as i64)
            .bind(index)
            .fetch_optional(&self.pool)
            .await?;
            let Some(row) = row else { break };
            let at = FrameTime {
                index: k,
                travel_mm: row.try_get(0)?,
                time_ms: row.try_get(1)?,
            };
            let particles = row.try_get::<i64, _>(2)?.max(0) as usize;
            part(particles, row.try_get(3)?);
            found = Some((at, particles));
        }
        Ok(found)
    }
}

/// Deletes job `job`'s frames: its run failed or was cancelled.
pub(super) async fn forget(tx: &mut super::database::WriteTx, job: &str) -> Result<()> {
    sqlx::query("DELETE FROM frames WHERE job_id = $1")
        .bind(job)
        .execute(&mut **tx)
        .await?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::service::store::{NewJob, Status};

    fn frame(k: u32, particles: usize, fill: u8) -> StoredFrame {
        StoredFrame {
            at: FrameTime {
                index: k,
                travel_mm: k as f64 * 0.5,
                time_ms: k as f64 * 0.25,
            },
            particles,
            data: vec![fill; particles * FRAME_BYTES_PER_PARTICLE],
        }
    }

    /// Every part of frame `k` in order, and where it stands.
    async fn read(
        store: &Store,
        id: Uuid,
        k: u32,
    ) -> Option<(FrameTime, usize, Vec<usize>, Vec<u8>)> {
        let (mut sizes, mut bytes) = (Vec::new(), Vec::new());
        let found = store
            .frame(id, k, |_, part| {
                sizes.push(part.len() / FRAME_BYTES_PER_PARTICLE);
                bytes.extend_from_slice(part);
            })
            .await
            .unwrap();
        found.map(|(at, n)| (at, n, sizes, bytes))
    }

    #[tokio::test]
    async fn a_frame_of_two_parts_and_one_particle_reads_back_whole_part_by_part_and_a_rerun_replaces_it(
    ) {
        let (_dir, store) = crate::service::store::temp_store().await;
        let job = NewJob {
            id: Uuid::new_v4(),
            case_json: "{}".into(),
            label: None,
            particles: 10,
            idempotency_key: None,
        };
        store.submit(job.clone(), 10).await.unwrap();
        let claim = store.claim("a").await.unwrap().unwrap();
        let n = 2 * PART_PARTICLES + 1;
        for k in [1, 0] {
            assert!(store
                .save_frame(job.id, claim.lease, &frame(k, n, 7))
                .await
                .unwrap());
        }
        let times = store.frame_times(job.id).await.unwrap();
        assert_eq!(times.iter().map(|t| t.index).collect::<Vec<_>>(), [0, 1]);
        assert_eq!(times[1].travel_mm, 0.5);
        let (at, particles, sizes, bytes) = read(&store, job.id, 1).await.unwrap();
        assert_eq!((at, particles), (frame(1, 0, 0).at, n));
        assert_eq!(sizes, [PART_PARTICLES, PART_PARTICLES, 1]);
        assert_eq!(bytes, frame(1, n, 7).data);
        assert!(read(&store, job.id, 2).await.is_none());
        // The run starts over with fewer particles written: only the new parts are left.
        assert!(store
            .save_frame(job.id, claim.lease, &frame(1, 3, 9))
            .await
            .unwrap());
        let (_, particles, sizes, bytes) = read(&store, job.id, 1).await.unwrap();
        assert_eq!((particles, sizes), (3, vec![3]));
        assert_eq!(bytes, frame(1, 3, 9).data);
        // A cancelled run keeps none; a lost lease writes none.
        store
            .finish_unsuccessful(job.id, claim.lease, Status::Cancelled, None)
            .await
            .unwrap();
        assert!(store.frame_times(job.id).await.unwrap().is_empty());
        assert!(!store
            .save_frame(job.id, claim.lease, &frame(0, 3, 1))
            .await
            .unwrap());
        assert!(store.frame_times(job.id).await.unwrap().is_empty());
    }
}
