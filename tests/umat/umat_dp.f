C     Drucker-Prager perfect plasticity in the Abaqus UMAT form, for the
C     empm UMAT adapter tests (tests/umat): the algorithm of empm's
C     native drucker_prager model (src/material/
C     empm_material_drucker_prager.f90, docs/materials.md), written
C     with the same operations in the same order, so that the two agree
C     to round-off. Tension positive, m = tr(sigma)/3, t = sqrt(J2):
C       yield f = t + eta m - xi c <= 0, tension cut-off m <= T,
C       potential g = t + eta_psi m; closed-form returns to the cone,
C       the cut-off or their corner (the apex when T = xi c/eta).
C
C     PROPS(1) = E, PROPS(2) = nu, PROPS(3) = cohesion c,
C     PROPS(4) = friction angle phi [deg], PROPS(5) = dilatancy angle
C     psi [deg] (<= phi), PROPS(6) = tension cut-off T (< 0: the apex),
C     PROPS(7) = Mohr-Coulomb match: 0 plane strain, 1 triaxial
C     compression (outer cone), 2 triaxial extension (inner cone),
C     PROPS(8) (optional) = 1: skip DDSDDE (an explicit code does not
C     use the Jacobian; for measuring the adapter against the native
C     model, which computes none), otherwise the algorithmic tangent.
C     A cut-off above the apex is clipped to it (the native model
C     refuses it as an input error).
C     STATEV(1) = eps_p_eq (accumulated sqrt(2/3 dep:dep)),
C     STATEV(2) = eps_p_vol (accumulated tr dep): NSTATV = 2.
C     SSE = the elastic stored energy m**2/(2K) + J2/(2G) of the new
C     stress (the native model's energy density).
C     Components 11, 22, 33, 12, 13, 23, engineering shear strains;
C     NTENS = 4 (plane strain, 1D) or 6. No SAVEd data: thread-safe.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      CHARACTER*80 CMNAME
      DIMENSION STRESS(NTENS),STATEV(NSTATV),
     1 DDSDDE(NTENS,NTENS),DDSDDT(NTENS),DRPLDE(NTENS),
     2 STRAN(NTENS),DSTRAN(NTENS),TIME(2),PREDEF(1),DPRED(1),
     3 PROPS(NPROPS),COORDS(3),DROT(3,3),DFGRD0(3,3),DFGRD1(3,3)
      DIMENSION S(6), SN(6), DE(6)
      PARAMETER (BIG = 1.D300)
C
C     Constants (as dp_init: Lame lambda, G, K; cone coefficients).
      E = PROPS(1)
      ANU = PROPS(2)
      C = PROPS(3)
      ALAMB = E*ANU/((1.D0+ANU)*(1.D0-2.D0*ANU))
      G = E/(2.D0*(1.D0+ANU))
      BK = E/(3.D0*(1.D0-2.D0*ANU))
      MATCH = NINT(PROPS(7))
      CALL DPMTCH(MATCH, PROPS(4), ETA, XI)
      CALL DPMTCH(MATCH, PROPS(5), ETAPSI, XIPSI)
      XIC = XI*C
      IF (XIC .LT. ETA*BIG) THEN
        APEX = XIC/ETA
      ELSE
        APEX = BIG
      END IF
      IF (PROPS(6) .LT. 0.D0) THEN
        T = APEX
        IF (APEX .LT. BIG) THEN
          TT = 0.D0
        ELSE
          TT = XIC
        END IF
      ELSE
        T = MIN(PROPS(6), APEX)
        TT = MAX(0.D0, XIC - ETA*T)
      END IF
      H = G + BK*ETA*ETAPSI
C
C     Elastic trial stress, in the native model's operation order
C     (2G de on the tensor shears = G times the engineering shear).
      TR = DSTRAN(1) + DSTRAN(2) + DSTRAN(3)
      DO 10 I = 1, NDI
        STRESS(I) = STRESS(I) + ALAMB*TR + 2.D0*G*DSTRAN(I)
   10 CONTINUE
      DO 20 I = NDI+1, NTENS
        STRESS(I) = STRESS(I) + G*DSTRAN(I)
   20 CONTINUE
C
C     Return mapping (empm_dp_return): mean stress, deviator, radius.
      AMTR = (STRESS(1) + STRESS(2) + STRESS(3))/3.D0
      DO 30 I = 1, 3
        S(I) = STRESS(I) - AMTR
   30 CONTINUE
      DO 40 I = 4, NTENS
        S(I) = STRESS(I)
   40 CONTINUE
C     The native sum runs over yz, xz, xy (here 23, 13, 12).
      SUMS = 0.5D0*(S(1)**2 + S(2)**2 + S(3)**2)
      IF (NTENS .EQ. 6) SUMS = SUMS + S(6)**2 + S(5)**2
      TTR = SQRT(SUMS + S(4)**2)
      F = TTR + ETA*AMTR - XIC
      AM = AMTR
      AT = TTR
      IF (F .LE. 0.D0 .AND. AMTR .LE. T) THEN
        IREG = 0
      ELSE
        IREG = 2
        IF (F .GT. 0.D0) THEN
          DLAM = F/H
          AT = TTR - G*DLAM
          AM = AMTR - BK*ETAPSI*DLAM
          IF (AT .GE. 0.D0 .AND. AM .LE. T) THEN
            IREG = 1
          ELSE IF (TTR .GT. TT) THEN
            IREG = 3
          END IF
        END IF
        IF (IREG .EQ. 1) THEN
          SCALE = AT/TTR
        ELSE IF (IREG .EQ. 3) THEN
          AM = T
          AT = TT
          SCALE = AT/TTR
        ELSE
          AM = T
          AT = TTR
          SCALE = 1.D0
        END IF
        DO 50 I = 1, 3
          STRESS(I) = SCALE*S(I) + AM
   50   CONTINUE
        DO 60 I = 4, NTENS
          STRESS(I) = SCALE*S(I)
   60   CONTINUE
        STATEV(1) = STATEV(1) + (TTR - AT)/(SQRT(3.D0)*G)
        STATEV(2) = STATEV(2) + (AMTR - AM)/BK
      END IF
C
C     Stored elastic energy of the new stress (dp_energy_density).
      AM2 = (STRESS(1) + STRESS(2) + STRESS(3))/3.D0
      SUMS = 0.D0
      DO 70 I = 1, 3
        SUMS = SUMS + (STRESS(I) - AM2)**2
   70 CONTINUE
      SUMS = 0.5D0*SUMS
      DO 80 I = NTENS, 4, -1
        SUMS = SUMS + STRESS(I)**2
   80 CONTINUE
      SSE = 0.5D0*AM2**2/BK + 0.5D0*SUMS/G
C
      IF (NPROPS .GE. 8) THEN
        IF (NINT(PROPS(8)) .EQ. 1) RETURN
      END IF
C
C     Algorithmic tangent (empm_dp_tangent) with engineering shears:
C     column J is the response to a unit DSTRAN(J), i.e. a tensor
C     shear of 1/2. SN = the unit normal s_tr/|s_tr| (tensor shears).
      DO 90 I = 1, 6
        SN(I) = 0.D0
   90 CONTINUE
      IF (TTR .GT. 0.D0) THEN
        DO 100 I = 1, NTENS
          SN(I) = S(I)/(SQRT(2.D0)*TTR)
  100   CONTINUE
      END IF
      BETA = 0.D0
      IF (IREG .EQ. 1) BETA = (TTR - AT)/TTR
      R2 = SQRT(2.D0)
      DO 150 J = 1, NTENS
        DO 110 I = 1, 6
          DE(I) = 0.D0
  110   CONTINUE
        IF (J .LE. 3) THEN
          DE(J) = 1.D0
        ELSE
          DE(J) = 0.5D0
        END IF
        DV = DE(1) + DE(2) + DE(3)
        DO 120 I = 1, 3
          DE(I) = DE(I) - DV/3.D0
  120   CONTINUE
        ANDE = SN(1)*DE(1) + SN(2)*DE(2) + SN(3)*DE(3)
        DO 130 I = 4, NTENS
          ANDE = ANDE + 2.D0*SN(I)*DE(I)
  130   CONTINUE
        DO 140 I = 1, NTENS
          IF (IREG .EQ. 0) THEN
            DS = 2.D0*G*DE(I)
            DM = BK*DV
          ELSE IF (IREG .EQ. 1) THEN
            DS = 2.D0*G*(1.D0 - BETA)*DE(I)
     1         + 2.D0*G*(BETA - G/H)*ANDE*SN(I)
     2         - (R2*G*BK*ETA/H)*DV*SN(I)
            DM = BK*(1.D0 - BK*ETA*ETAPSI/H)*DV
     1         - (R2*G*BK*ETAPSI/H)*ANDE
          ELSE IF (IREG .EQ. 2) THEN
            DS = 2.D0*G*DE(I)
            DM = 0.D0
          ELSE
            DS = 2.D0*G*(AT/TTR)*(DE(I) - ANDE*SN(I))
            DM = 0.D0
          END IF
          IF (I .LE. 3) DS = DS + DM
          DDSDDE(I,J) = DS
  140   CONTINUE
  150 CONTINUE
      RETURN
      END
C
C     Cone coefficients matched to Mohr-Coulomb with angle ANGLE [deg]
C     (empm_dp_match): MATCH 0 plane strain, 1 compression, 2 extension.
      SUBROUTINE DPMTCH(MATCH, ANGLE, ETA, XI)
      IMPLICIT DOUBLE PRECISION (A-H,O-Z)
      DEG = ACOS(-1.D0)/180.D0
      IF (MATCH .EQ. 1 .OR. MATCH .EQ. 2) THEN
        SA = SIN(ANGLE*DEG)
        IF (MATCH .EQ. 1) THEN
          D = SQRT(3.D0)*(3.D0 - SA)
        ELSE
          D = SQRT(3.D0)*(3.D0 + SA)
        END IF
        ETA = 6.D0*SA/D
        XI = 6.D0*COS(ANGLE*DEG)/D
      ELSE
        TA = TAN(ANGLE*DEG)
        D = SQRT(9.D0 + 12.D0*TA**2)
        ETA = 3.D0*TA/D
        XI = 3.D0/D
      END IF
      RETURN
      END
