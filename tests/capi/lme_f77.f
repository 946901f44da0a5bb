C     EMPM_LME_BASIS FROM FIXED-FORM FORTRAN 77, NO MODULE: TWO NODES
C     IN 1D, THE MIDPOINT GETS P = (1/2, 1/2).
      PROGRAM LMEF77
      IMPLICIT NONE
      DOUBLE PRECISION X(1), XA(1, 2), P(2), DP(1, 2), XLAM(1)
      INTEGER INFO
      X(1) = 0.5D0
      XA(1, 1) = 0.0D0
      XA(1, 2) = 1.0D0
      XLAM(1) = 0.0D0
      CALL EMPM_LME_BASIS(1, 2, X, XA, 1.0D0, 1.0D0, 1.0D-10,
     &                    P, DP, XLAM, INFO)
      IF (INFO .NE. 0) STOP 1
      IF (ABS(P(1) - 0.5D0) .GT. 1.0D-12) STOP 2
      IF (ABS(P(1) + P(2) - 1.0D0) .GT. 1.0D-12) STOP 3
      CALL EMPM_LME_BASIS(0, 2, X, XA, 1.0D0, 1.0D0, 1.0D-10,
     &                    P, DP, XLAM, INFO)
      IF (INFO .NE. -1) STOP 4
      WRITE (*, '(A)') ' EMPM_LME_BASIS FROM FORTRAN 77 OK'
      END
